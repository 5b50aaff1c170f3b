/*
 * Quadrature decoding of the pivot encoder, four counts per line.
 *
 * The input is the pin pair ab = (A << 1) | B sampled at each edge. Counting up, the pins step
 * through 00 -> 10 -> 11 -> 01 -> 00 (A leads B); counting down, the reverse. A sample that
 * differs from the last in both pins skipped a state (an edge was missed): the direction is
 * unknown, so the count is left alone and the transition counted as invalid.
 */
#ifndef RIG_QUADRATURE_H
#define RIG_QUADRATURE_H

#include <stdint.h>

#define QUADRATURE_INVALID 2

typedef struct {
	uint8_t state;
	int32_t count;
	uint16_t invalid;
} quadrature_t;

void quadrature_init(quadrature_t *decoder, uint8_t ab);

/* Returns +1 or -1 for a step, 0 when the pins did not change, QUADRATURE_INVALID for a skip. */
int8_t quadrature_update(quadrature_t *decoder, uint8_t ab);

#endif
