#include "photodiode.h"

/* Samples further apart than this (about 2 s) are not interpolated: span * part must fit 32 bits. */
#define MAX_INTERPOLATION_SPAN 0x3FFFFFUL

void photodiode_init(photodiode_t *detector, uint16_t rise, uint16_t fall)
{
	detector->rise = rise;
	detector->fall = fall;
	detector->high = 0;
	detector->primed = 0;
	detector->window_open = 0;
}

/* The time between two samples at which the line through them reaches `level`. */
static uint32_t interpolate(uint32_t from_tick, uint32_t to_tick, uint16_t from_value,
			    uint16_t to_value, uint16_t level)
{
	uint32_t span = to_tick - from_tick;
	if (span > MAX_INTERPOLATION_SPAN)
		return to_tick;
	uint16_t step = from_value < to_value ? to_value - from_value : from_value - to_value;
	uint16_t part = from_value < to_value ? level - from_value : from_value - level;
	return from_tick + (span * part + step / 2) / step;
}

static void update_crossing(photodiode_t *detector, uint16_t value, uint32_t tick, photodiode_event_t *event)
{
	if (!detector->primed) {
		detector->primed = 1;
		detector->high = value >= detector->rise;
	} else if (!detector->high && value >= detector->rise) {
		detector->high = 1;
		event->crossing = 1;
		event->crossing_tick = interpolate(detector->last_tick, tick, detector->last_value, value, detector->rise);
	} else if (detector->high && value <= detector->fall) {
		detector->high = 0;
		event->crossing = -1;
		event->crossing_tick = interpolate(detector->last_tick, tick, detector->last_value, value, detector->fall);
	}
	detector->last_value = value;
	detector->last_tick = tick;
}

static void update_passage(photodiode_t *detector, uint16_t value, uint32_t tick, uint8_t first, photodiode_event_t *event)
{
	if (value > detector->fall) {
		if (!detector->window_open) {
			detector->window_open = 1;
			detector->window_whole = !first;
			detector->window_rose = 0;
			detector->window_start = tick;
			detector->weighted_ticks = 0;
			detector->weight = 0;
			detector->peak = 0;
		}
		uint16_t excess = value - detector->fall;
		detector->weighted_ticks += (uint64_t)excess * (tick - detector->window_start);
		detector->weight += excess;
		detector->window_last = tick;
		if (value > detector->peak)
			detector->peak = value;
		if (event->crossing > 0)
			detector->window_rose = 1;
		return;
	}
	if (!detector->window_open)
		return;
	detector->window_open = 0;
	if (detector->window_whole && detector->window_rose) {
		event->passage = 1;
		event->start_tick = detector->window_start;
		event->centroid_tick = detector->window_start +
				       (uint32_t)((detector->weighted_ticks + detector->weight / 2) / detector->weight);
		event->end_tick = detector->window_last;
		event->peak = detector->peak;
	}
}

void photodiode_update(photodiode_t *detector, uint16_t value, uint32_t tick, photodiode_event_t *event)
{
	uint8_t first = !detector->primed;
	event->crossing = 0;
	event->passage = 0;
	update_crossing(detector, value, tick, event);
	update_passage(detector, value, tick, first, event);
}
