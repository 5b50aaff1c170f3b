/*
 * The LED's blink code: a pseudo-random bit sequence played at scheduled board times, so that a
 * camera filming the LED can find where its frames fall on the board's clock (protocol.h gives
 * the LFSR). Bit k starts at start_tick + k * bit_ticks; after the last bit the LED goes off.
 */
#ifndef RIG_BLINK_H
#define RIG_BLINK_H

#include <stdbool.h>
#include <stdint.h>

#include "protocol.h"

/* Advances the LFSR one step and returns the bit shifted out. */
uint8_t blink_lfsr_next(uint16_t *state);

typedef struct {
	bool active;
	uint32_t next_tick;
	uint32_t bit_ticks;
	uint16_t next_bit;
	uint16_t bits;
	uint16_t lfsr;
	uint8_t level;
} blink_t;

void blink_start(blink_t *blink, const rig_cmd_blink_t *command);

/* Whether the next change is due at `now`. */
bool blink_due(const blink_t *blink, uint32_t now);

/* Ticks from `now` to the next change (0 when due). */
uint32_t blink_wait(const blink_t *blink, uint32_t now);

/* Takes the change that is due: returns the LED level and sets *bit to its bit index (bits for
 * the switch-off after the last bit, which also ends the blink). */
uint8_t blink_advance(blink_t *blink, uint16_t *bit);

#endif
