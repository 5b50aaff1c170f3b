#include "blink.h"

uint8_t blink_lfsr_next(uint16_t *state)
{
	uint8_t out = *state & 1;
	*state >>= 1;
	if (out)
		*state ^= RIG_BLINK_LFSR_TAPS;
	return out;
}

void blink_start(blink_t *blink, const rig_cmd_blink_t *command)
{
	blink->active = true;
	blink->next_tick = command->start_tick;
	blink->bit_ticks = command->bit_ticks;
	blink->next_bit = 0;
	blink->bits = command->bits;
	blink->lfsr = command->seed;
	blink->level = command->level;
}

bool blink_due(const blink_t *blink, uint32_t now)
{
	return blink->active && (int32_t)(now - blink->next_tick) >= 0;
}

uint32_t blink_wait(const blink_t *blink, uint32_t now)
{
	int32_t wait = (int32_t)(blink->next_tick - now);
	return wait > 0 ? (uint32_t)wait : 0;
}

uint8_t blink_advance(blink_t *blink, uint16_t *bit)
{
	*bit = blink->next_bit;
	if (blink->next_bit == blink->bits) {
		blink->active = false;
		return 0;
	}
	uint8_t level = blink_lfsr_next(&blink->lfsr) ? blink->level : 0;
	blink->next_bit++;
	blink->next_tick += blink->bit_ticks;
	return level;
}
