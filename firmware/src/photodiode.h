/*
 * The photodiode signal: threshold crossings with hysteresis, and passages of a bright object.
 *
 * Crossings: the detector goes high once a sample reaches `rise` and low once a sample drops to
 * `fall` (fall < rise), so noise smaller than rise - fall cannot make it chatter. The crossing
 * time is interpolated linearly between the two samples around the threshold crossed. The first
 * sample only sets the state.
 *
 * Passages: a window opens at the first sample above `fall` and closes at the next at or below
 * it; if the detector rose in between, the window is a passage, reported with the time centroid
 * of its samples weighted by (sample - fall). Both ends of the window are at the same level, so
 * for a symmetric brightness profile the centroid is the moment of the peak, whatever the
 * hysteresis. A window already open at the first sample is not reported.
 */
#ifndef RIG_PHOTODIODE_H
#define RIG_PHOTODIODE_H

#include <stdint.h>

typedef struct {
	int8_t crossing; /* +1 rising, -1 falling, 0 none */
	uint32_t crossing_tick;
	uint8_t passage; /* 1 when a passage ended with this sample */
	uint32_t start_tick;
	uint32_t centroid_tick;
	uint32_t end_tick;
	uint16_t peak;
} photodiode_event_t;

typedef struct {
	uint16_t rise;
	uint16_t fall;
	uint8_t high;
	uint8_t primed;
	uint16_t last_value;
	uint32_t last_tick;
	uint8_t window_open;
	uint8_t window_whole; /* opened from below fall, not mid-passage */
	uint8_t window_rose;
	uint32_t window_start;
	uint32_t window_last;
	uint64_t weighted_ticks;
	uint32_t weight;
	uint16_t peak;
} photodiode_t;

void photodiode_init(photodiode_t *detector, uint16_t rise, uint16_t fall);

/* Feeds one sample; fills *event. Ticks may wrap: only differences are used. */
void photodiode_update(photodiode_t *detector, uint16_t value, uint32_t tick, photodiode_event_t *event);

#endif
