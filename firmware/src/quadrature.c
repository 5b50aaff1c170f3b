#include "quadrature.h"

/* Position of each pin pair along the counting-up cycle 00, 10, 11, 01. */
static uint8_t cycle_position(uint8_t ab)
{
	static const uint8_t position[4] = {0, 3, 1, 2};
	return position[ab & 3];
}

void quadrature_init(quadrature_t *decoder, uint8_t ab)
{
	decoder->state = ab & 3;
	decoder->count = 0;
	decoder->invalid = 0;
}

int8_t quadrature_update(quadrature_t *decoder, uint8_t ab)
{
	uint8_t delta = (uint8_t)(cycle_position(ab) - cycle_position(decoder->state)) & 3;
	decoder->state = ab & 3;
	switch (delta) {
	case 0:
		return 0;
	case 1:
		decoder->count++;
		return 1;
	case 3:
		decoder->count--;
		return -1;
	default:
		decoder->invalid++;
		return QUADRATURE_INVALID;
	}
}
