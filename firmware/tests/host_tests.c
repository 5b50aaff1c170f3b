/*
 * Host-side unit tests of the firmware's logic (framing, CRC, queues, quadrature decoding,
 * photodiode crossings with hysteresis and passages, command parsing, blink code), compiled with the host's C compiler.
 * Prints one line per failed check and closes with "N passed, N failed"; exits 1 on a failure.
 */
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "blink.h"
#include "cobs.h"
#include "command.h"
#include "crc16.h"
#include "frame.h"
#include "photodiode.h"
#include "protocol.h"
#include "quadrature.h"
#include "queue.h"

static int tests_passed;
static int tests_failed;
static int checks_failed_in_test;

#define CHECK(condition) check((condition), #condition, __FILE__, __LINE__)
#define CHECK_EQ(actual, expected) check_equal((long long)(actual), (long long)(expected), #actual, __FILE__, __LINE__)

static void check(bool ok, const char *what, const char *file, int line)
{
	if (!ok) {
		checks_failed_in_test++;
		printf("  check failed at %s:%d: %s\n", file, line, what);
	}
}

static void check_equal(long long actual, long long expected, const char *what, const char *file, int line)
{
	if (actual != expected) {
		checks_failed_in_test++;
		printf("  check failed at %s:%d: %s is %lld, expected %lld\n", file, line, what, actual, expected);
	}
}

static void run(void (*test)(void), const char *name)
{
	checks_failed_in_test = 0;
	test();
	if (checks_failed_in_test) {
		tests_failed++;
		printf("FAIL %s\n", name);
	} else {
		tests_passed++;
	}
}

#define RUN(test) run(test, #test)

/* A seeded xorshift generator, so random inputs are the same on every run. */
static uint32_t random_state = 0x12345678;

static uint32_t random_next(void)
{
	random_state ^= random_state << 13;
	random_state ^= random_state >> 17;
	random_state ^= random_state << 5;
	return random_state;
}

static uint16_t crc16_bitwise(const uint8_t *data, size_t length)
{
	uint16_t crc = 0xFFFF;
	for (size_t i = 0; i < length; i++) {
		crc ^= (uint16_t)(data[i] << 8);
		for (int bit = 0; bit < 8; bit++)
			crc = (crc & 0x8000) ? (uint16_t)((crc << 1) ^ 0x1021) : (uint16_t)(crc << 1);
	}
	return crc;
}

/* Feeds bytes to a receiver; returns the result at the last byte. */
static frame_result_t receive_all(frame_receiver_t *receiver, const uint8_t *bytes, size_t length, frame_t *frame)
{
	frame_result_t result = FRAME_PENDING;
	for (size_t i = 0; i < length; i++)
		result = frame_receive(receiver, bytes[i], frame);
	return result;
}

/* ---- CRC ---- */

static void test_crc_check_value(void)
{
	CHECK_EQ(crc16((const uint8_t *)"123456789", 9), 0x29B1);
	CHECK_EQ(crc16(NULL, 0), RIG_CRC16_INIT);
}

static void test_crc_table_matches_bitwise_definition(void)
{
	uint8_t data[64];
	for (int round = 0; round < 200; round++) {
		size_t length = random_next() % sizeof data;
		for (size_t i = 0; i < length; i++)
			data[i] = (uint8_t)random_next();
		CHECK_EQ(crc16(data, length), crc16_bitwise(data, length));
	}
}

static void test_crc_catches_every_single_bit_error(void)
{
	uint8_t data[20];
	for (size_t i = 0; i < sizeof data; i++)
		data[i] = (uint8_t)(i * 37);
	uint16_t good = crc16(data, sizeof data);
	int missed = 0;
	for (size_t bit = 0; bit < 8 * sizeof data; bit++) {
		data[bit / 8] ^= (uint8_t)(1 << (bit % 8));
		missed += crc16(data, sizeof data) == good;
		data[bit / 8] ^= (uint8_t)(1 << (bit % 8));
	}
	CHECK_EQ(missed, 0);
}

/* ---- COBS ---- */

static void check_cobs_round_trip(const uint8_t *data, size_t length)
{
	uint8_t encoded[COBS_MAX_ENCODED(600)];
	uint8_t decoded[600];
	size_t encoded_length = cobs_encode(data, length, encoded);
	CHECK(encoded_length <= COBS_MAX_ENCODED(length));
	CHECK(memchr(encoded, 0, encoded_length) == NULL);
	int decoded_length = cobs_decode(encoded, encoded_length, decoded, sizeof decoded);
	CHECK_EQ(decoded_length, (long long)length);
	CHECK(decoded_length >= 0 && memcmp(decoded, data, length) == 0);
}

static void test_cobs_round_trips_edge_cases(void)
{
	uint8_t data[600] = {0};
	check_cobs_round_trip(data, 0);
	check_cobs_round_trip(data, 1);
	check_cobs_round_trip(data, 300);
	memset(data, 0x11, sizeof data);
	check_cobs_round_trip(data, 253);
	check_cobs_round_trip(data, 254);
	check_cobs_round_trip(data, 255);
	check_cobs_round_trip(data, 600);
	data[254] = 0;
	check_cobs_round_trip(data, 255);
	check_cobs_round_trip(data, 256);
}

static void test_cobs_round_trips_random_data(void)
{
	uint8_t data[600];
	for (int round = 0; round < 300; round++) {
		size_t length = random_next() % sizeof data;
		for (size_t i = 0; i < length; i++)
			data[i] = (random_next() % 4 == 0) ? 0 : (uint8_t)random_next();
		check_cobs_round_trip(data, length);
	}
}

static void test_cobs_rejects_malformed_input(void)
{
	uint8_t out[16];
	const uint8_t zero_inside[] = {3, 1, 0};
	const uint8_t block_past_end[] = {5, 1, 2};
	const uint8_t zero_code[] = {0};
	const uint8_t too_long[] = {6, 1, 2, 3, 4, 5};
	CHECK_EQ(cobs_decode(zero_inside, sizeof zero_inside, out, sizeof out), -1);
	CHECK_EQ(cobs_decode(block_past_end, sizeof block_past_end, out, sizeof out), -1);
	CHECK_EQ(cobs_decode(zero_code, sizeof zero_code, out, sizeof out), -1);
	CHECK_EQ(cobs_decode(too_long, sizeof too_long, out, 4), -1);
}

/* ---- frames ---- */

static void test_frame_round_trip(void)
{
	uint8_t payload[RIG_FRAME_MAX_PAYLOAD];
	for (size_t i = 0; i < sizeof payload; i++)
		payload[i] = (uint8_t)(i % 3 ? i : 0);
	uint8_t encoded[RIG_FRAME_MAX_ENCODED];
	for (uint8_t length = 0; length <= RIG_FRAME_MAX_PAYLOAD; length++) {
		uint8_t size = frame_encode(RIG_MSG_ENCODER, (uint8_t)(200 + length), payload, length, encoded);
		CHECK(size > 0 && size <= RIG_FRAME_MAX_ENCODED);
		CHECK_EQ(encoded[size - 1], RIG_FRAME_DELIMITER);
		CHECK(memchr(encoded, 0, size - 1) == NULL);
		frame_receiver_t receiver;
		frame_receiver_init(&receiver);
		frame_t frame;
		CHECK_EQ(receive_all(&receiver, encoded, size, &frame), FRAME_OK);
		CHECK_EQ(frame.type, RIG_MSG_ENCODER);
		CHECK_EQ(frame.seq, (uint8_t)(200 + length));
		CHECK_EQ(frame.length, length);
		CHECK(memcmp(frame.payload, payload, length) == 0);
	}
}

static void test_frame_rejects_payload_over_maximum(void)
{
	uint8_t payload[RIG_FRAME_MAX_PAYLOAD + 1] = {0};
	uint8_t encoded[RIG_FRAME_MAX_ENCODED + 2];
	CHECK_EQ(frame_encode(RIG_MSG_ACK, 0, payload, sizeof payload, encoded), 0);
}

static void test_frame_with_any_corrupted_byte_is_rejected(void)
{
	const uint8_t payload[] = {1, 2, 3, 0, 5, 6};
	uint8_t encoded[RIG_FRAME_MAX_ENCODED];
	uint8_t size = frame_encode(RIG_MSG_SAMPLE, 7, payload, sizeof payload, encoded);
	for (uint8_t at = 0; at + 1 < size; at++) {
		for (int flip = 1; flip < 256; flip <<= 1) {
			uint8_t damaged[RIG_FRAME_MAX_ENCODED];
			memcpy(damaged, encoded, size);
			damaged[at] ^= (uint8_t)flip;
			frame_receiver_t receiver;
			frame_receiver_init(&receiver);
			frame_t frame;
			/* A flip that makes a zero splits the frame: then no piece may pass as good. */
			for (uint8_t i = 0; i < size; i++) {
				frame_result_t result = frame_receive(&receiver, damaged[i], &frame);
				CHECK(result != FRAME_OK);
			}
		}
	}
}

static void test_frame_truncated_empty_and_oversize(void)
{
	frame_receiver_t receiver;
	frame_receiver_init(&receiver);
	frame_t frame;
	const uint8_t two_bytes[] = {3, 0x80, 0x01, 0};
	CHECK_EQ(receive_all(&receiver, two_bytes, sizeof two_bytes, &frame), FRAME_TRUNCATED);
	const uint8_t idle[] = {0};
	CHECK_EQ(receive_all(&receiver, idle, sizeof idle, &frame), FRAME_EMPTY);
	uint8_t long_run[100];
	memset(long_run, 0x42, sizeof long_run);
	CHECK_EQ(receive_all(&receiver, long_run, sizeof long_run, &frame), FRAME_PENDING);
	CHECK_EQ(receive_all(&receiver, idle, sizeof idle, &frame), FRAME_OVERSIZE);

	/* After all that, a good frame still comes through. */
	uint8_t encoded[RIG_FRAME_MAX_ENCODED];
	uint8_t size = frame_encode(RIG_MSG_ACK, 9, "abc", 3, encoded);
	CHECK_EQ(receive_all(&receiver, encoded, size, &frame), FRAME_OK);
	CHECK_EQ(frame.seq, 9);
}

static void test_frame_recovered_after_random_noise(void)
{
	uint8_t encoded[RIG_FRAME_MAX_ENCODED];
	uint8_t size = frame_encode(RIG_MSG_LED, 42, "\x01\x02\x03\x04", 4, encoded);
	for (int round = 0; round < 100; round++) {
		frame_receiver_t receiver;
		frame_receiver_init(&receiver);
		frame_t frame;
		int good = 0;
		int noise = (int)(random_next() % 80);
		for (int i = 0; i < noise; i++)
			good += frame_receive(&receiver, (uint8_t)random_next(), &frame) == FRAME_OK;
		/* The frame right after the noise may be merged with its tail; the next must decode. */
		for (int copy = 0; copy < 2; copy++)
			for (uint8_t i = 0; i < size; i++)
				good += frame_receive(&receiver, encoded[i], &frame) == FRAME_OK && frame.seq == 42;
		CHECK(good >= 1);
	}
}

/* ---- queues ---- */

QUEUE_DEFINE(test_queue, uint16_t, 8)

static void test_queue_keeps_order_and_counts_overflow(void)
{
	test_queue_t queue = {0};
	for (uint16_t i = 0; i < 8; i++)
		CHECK(test_queue_push(&queue, (uint16_t)(100 + i)));
	CHECK_EQ(test_queue_count(&queue), 8);
	CHECK_EQ(test_queue_free(&queue), 0);
	for (uint16_t i = 0; i < 5; i++)
		CHECK(!test_queue_push(&queue, 999));
	CHECK_EQ(queue.overflow, 5);
	uint16_t item;
	for (uint16_t i = 0; i < 8; i++) {
		CHECK(test_queue_pop(&queue, &item));
		CHECK_EQ(item, 100 + i);
	}
	CHECK(!test_queue_pop(&queue, &item));
	CHECK(test_queue_empty(&queue));
}

static void test_queue_wraps_its_indices(void)
{
	test_queue_t queue = {0};
	uint16_t next_in = 0;
	uint16_t next_out = 0;
	for (int round = 0; round < 2000; round++) {
		int pushes = (int)(random_next() % 4);
		for (int i = 0; i < pushes; i++)
			if (test_queue_push(&queue, next_in))
				next_in++;
		int pops = (int)(random_next() % 4);
		uint16_t item;
		for (int i = 0; i < pops; i++)
			if (test_queue_pop(&queue, &item))
				CHECK_EQ(item, next_out++);
		CHECK_EQ(test_queue_count(&queue), (uint16_t)(next_in - next_out));
	}
	CHECK(next_out > 1000);
}

/* ---- quadrature ---- */

static const uint8_t forward_cycle[4] = {0, 2, 3, 1}; /* 00, 10, 11, 01 */

static void test_quadrature_counts_both_directions(void)
{
	quadrature_t decoder;
	quadrature_init(&decoder, 0);
	for (int i = 1; i <= 40; i++)
		CHECK_EQ(quadrature_update(&decoder, forward_cycle[i % 4]), 1);
	CHECK_EQ(decoder.count, 40);
	for (int i = 39; i >= 0; i--)
		CHECK_EQ(quadrature_update(&decoder, forward_cycle[(i + 400) % 4]), -1);
	CHECK_EQ(decoder.count, 0);
	CHECK_EQ(decoder.invalid, 0);
}

static void test_quadrature_reverses_mid_cycle(void)
{
	quadrature_t decoder;
	quadrature_init(&decoder, forward_cycle[1]);
	CHECK_EQ(quadrature_update(&decoder, forward_cycle[2]), 1);
	CHECK_EQ(quadrature_update(&decoder, forward_cycle[1]), -1);
	CHECK_EQ(quadrature_update(&decoder, forward_cycle[0]), -1);
	CHECK_EQ(quadrature_update(&decoder, forward_cycle[3]), -1);
	CHECK_EQ(quadrature_update(&decoder, forward_cycle[3]), 0);
	CHECK_EQ(decoder.count, -2);
}

static void test_quadrature_invalid_transitions_keep_count(void)
{
	quadrature_t decoder;
	quadrature_init(&decoder, 0);
	CHECK_EQ(quadrature_update(&decoder, 2), 1);
	CHECK_EQ(quadrature_update(&decoder, 1), QUADRATURE_INVALID); /* 10 -> 01 skips 11 */
	CHECK_EQ(decoder.count, 1);
	CHECK_EQ(quadrature_update(&decoder, 2), QUADRATURE_INVALID); /* and back */
	CHECK_EQ(quadrature_update(&decoder, 3), 1);                  /* counting resumes */
	CHECK_EQ(decoder.count, 2);
	CHECK_EQ(decoder.invalid, 2);
	for (uint8_t from = 0; from < 4; from++) {
		quadrature_init(&decoder, from);
		CHECK_EQ(quadrature_update(&decoder, from ^ 3), QUADRATURE_INVALID);
		CHECK_EQ(decoder.count, 0);
	}
}

/* ---- photodiode ---- */

static int8_t feed(photodiode_t *detector, uint16_t value, uint32_t tick, uint32_t *crossing_tick)
{
	photodiode_event_t event;
	photodiode_update(detector, value, tick, &event);
	if (event.crossing)
		*crossing_tick = event.crossing_tick;
	return event.crossing;
}

static void test_photodiode_first_sample_only_primes(void)
{
	photodiode_t detector;
	photodiode_init(&detector, 500, 300);
	uint32_t tick = 0;
	CHECK_EQ(feed(&detector, 900, 10, &tick), 0);
	CHECK_EQ(feed(&detector, 800, 20, &tick), 0);
	CHECK_EQ(feed(&detector, 100, 30, &tick), -1);
}

static void test_photodiode_hysteresis_ignores_noise_inside_band(void)
{
	photodiode_t detector;
	photodiode_init(&detector, 500, 300);
	uint32_t tick = 0;
	int crossings = 0;
	crossings += feed(&detector, 100, 0, &tick) != 0;
	for (uint32_t i = 1; i < 1000; i++)
		crossings += feed(&detector, (uint16_t)(301 + random_next() % 199), i * 10, &tick) != 0;
	CHECK_EQ(crossings, 0);
	CHECK_EQ(feed(&detector, 500, 10000, &tick), 1);
	for (uint32_t i = 1; i < 1000; i++)
		crossings += feed(&detector, (uint16_t)(301 + random_next() % 199), 10000 + i * 10, &tick) != 0;
	CHECK_EQ(crossings, 0);
}

static void test_photodiode_interpolates_crossing_times(void)
{
	photodiode_t detector;
	photodiode_init(&detector, 500, 300);
	uint32_t tick = 0;
	feed(&detector, 400, 1000, &tick);
	CHECK_EQ(feed(&detector, 600, 1200, &tick), 1);
	CHECK_EQ(tick, 1100);
	feed(&detector, 700, 1400, &tick);
	CHECK_EQ(feed(&detector, 200, 1600, &tick), -1);
	CHECK_EQ(tick, 1400 + 160);
}

static void test_photodiode_crossing_across_tick_wrap(void)
{
	photodiode_t detector;
	photodiode_init(&detector, 500, 300);
	uint32_t tick = 0;
	feed(&detector, 0, 0xFFFFFF00u, &tick);
	CHECK_EQ(feed(&detector, 1000, 0x100u, &tick), 1);
	CHECK_EQ(tick, 0u);
}

/* A triangular pulse of height 800 over a baseline of 100, centred at `centre`, 4000 ticks wide
 * at the base, sampled every 208 ticks from `first`. Returns the passage reported. */
static photodiode_event_t play_pulse(photodiode_t *detector, uint32_t first, uint32_t centre, int *passages)
{
	photodiode_event_t passage = {0};
	*passages = 0;
	for (int i = 0; i < 60; i++) {
		uint32_t tick = first + (uint32_t)i * 208u;
		int32_t distance = (int32_t)(tick - centre);
		int32_t away = distance < 0 ? -distance : distance;
		uint16_t value = (uint16_t)(100 + (away < 2000 ? 800 * (2000 - away) / 2000 : 0));
		photodiode_event_t event;
		photodiode_update(detector, value, tick, &event);
		if (event.passage) {
			passage = event;
			(*passages)++;
		}
	}
	return passage;
}

static void test_photodiode_passage_centroid_is_pulse_centre_despite_hysteresis(void)
{
	for (uint32_t phase = 0; phase < 208; phase += 13) {
		photodiode_t detector;
		photodiode_init(&detector, 700, 200);
		int passages;
		photodiode_event_t passage = play_pulse(&detector, 1000 + phase, 7000, &passages);
		CHECK_EQ(passages, 1);
		/* Sampling a triangle every 208 ticks leaves at most a few ticks of error. */
		CHECK((int32_t)(passage.centroid_tick - 7000) >= -4 && (int32_t)(passage.centroid_tick - 7000) <= 4);
		CHECK(passage.start_tick < 7000 - 1500 && passage.end_tick > 7000 + 1500);
		CHECK(passage.peak >= 900 - 100 && passage.peak <= 900);
	}
}

static void test_photodiode_passage_across_tick_wrap(void)
{
	photodiode_t detector;
	photodiode_init(&detector, 700, 200);
	int passages;
	photodiode_event_t passage = play_pulse(&detector, 0xFFFFE000u, 0xFFFFFF00u, &passages);
	CHECK_EQ(passages, 1);
	CHECK((int32_t)(passage.centroid_tick - 0xFFFFFF00u) >= -4 && (int32_t)(passage.centroid_tick - 0xFFFFFF00u) <= 4);
}

static void test_photodiode_bump_below_rise_is_no_passage(void)
{
	photodiode_t detector;
	photodiode_init(&detector, 950, 200);
	int passages;
	play_pulse(&detector, 1000, 7000, &passages);
	CHECK_EQ(passages, 0);
}

static void test_photodiode_passage_under_way_at_start_is_not_reported(void)
{
	photodiode_t detector;
	photodiode_init(&detector, 700, 200);
	int passages;
	play_pulse(&detector, 6000, 7000, &passages);
	CHECK_EQ(passages, 0);
	play_pulse(&detector, 20000, 26000, &passages);
	CHECK_EQ(passages, 1);
}

/* ---- commands ---- */

static frame_t command_frame(uint8_t type, const void *payload, uint8_t length)
{
	frame_t frame = {.type = type, .seq = 17, .length = length};
	if (length)
		memcpy(frame.payload, payload, length);
	return frame;
}

static uint8_t parse(uint8_t type, const void *payload, uint8_t length, command_t *command)
{
	frame_t frame = command_frame(type, payload, length);
	return command_parse(&frame, 1000, command);
}

static void test_command_parser_accepts_valid_commands(void)
{
	command_t command;
	CHECK_EQ(parse(RIG_CMD_IDENTIFY, NULL, 0, &command), RIG_STATUS_OK);
	CHECK_EQ(command.seq, 17);
	CHECK_EQ(parse(RIG_CMD_SYNC, NULL, 0, &command), RIG_STATUS_OK);
	CHECK_EQ(parse(RIG_CMD_STATUS, NULL, 0, &command), RIG_STATUS_OK);
	rig_cmd_led_t led = {128};
	CHECK_EQ(parse(RIG_CMD_LED, &led, sizeof led, &command), RIG_STATUS_OK);
	CHECK_EQ(command.args.led.level, 128);
	rig_cmd_blink_t blink = {2000, 40000, 0xACE1, 64, 255};
	CHECK_EQ(parse(RIG_CMD_BLINK, &blink, sizeof blink, &command), RIG_STATUS_OK);
	CHECK_EQ(command.args.blink.bit_ticks, 40000);
	CHECK_EQ(command.args.blink.seed, 0xACE1);
	rig_cmd_encoder_t encoder = {0};
	CHECK_EQ(parse(RIG_CMD_ENCODER, &encoder, sizeof encoder, &command), RIG_STATUS_OK);
	encoder.report_ticks = RIG_ENCODER_MIN_REPORT_TICKS;
	CHECK_EQ(parse(RIG_CMD_ENCODER, &encoder, sizeof encoder, &command), RIG_STATUS_OK);
	rig_cmd_photodiode_t photodiode = {600, 400, 0};
	CHECK_EQ(parse(RIG_CMD_PHOTODIODE, &photodiode, sizeof photodiode, &command), RIG_STATUS_OK);
	CHECK_EQ(command.args.photodiode.rise, 600);
	CHECK_EQ(command.args.photodiode.fall, 400);
	rig_cmd_stream_t stream = {RIG_STREAM_ENCODER | RIG_STREAM_PHOTODIODE | RIG_STREAM_SAMPLES};
	CHECK_EQ(parse(RIG_CMD_STREAM, &stream, sizeof stream, &command), RIG_STATUS_OK);
}

static void test_command_parser_rejects_unknown_types_and_lengths(void)
{
	command_t command;
	uint8_t payload[RIG_FRAME_MAX_PAYLOAD] = {0};
	CHECK_EQ(parse(0x7F, NULL, 0, &command), RIG_STATUS_UNKNOWN_COMMAND);
	CHECK_EQ(parse(RIG_MSG_ACK, NULL, 0, &command), RIG_STATUS_UNKNOWN_COMMAND);
	CHECK_EQ(command.type, RIG_MSG_ACK);
	CHECK_EQ(parse(RIG_CMD_IDENTIFY, payload, 1, &command), RIG_STATUS_BAD_LENGTH);
	const struct {
		uint8_t type;
		uint8_t length;
	} sized[] = {
		{RIG_CMD_LED, sizeof(rig_cmd_led_t)},
		{RIG_CMD_BLINK, sizeof(rig_cmd_blink_t)},
		{RIG_CMD_ENCODER, sizeof(rig_cmd_encoder_t)},
		{RIG_CMD_PHOTODIODE, sizeof(rig_cmd_photodiode_t)},
		{RIG_CMD_STREAM, sizeof(rig_cmd_stream_t)},
	};
	for (size_t i = 0; i < sizeof sized / sizeof sized[0]; i++) {
		CHECK_EQ(parse(sized[i].type, payload, sized[i].length - 1, &command), RIG_STATUS_BAD_LENGTH);
		CHECK_EQ(parse(sized[i].type, payload, sized[i].length + 1, &command), RIG_STATUS_BAD_LENGTH);
	}
}

static void test_command_parser_rejects_out_of_range_values(void)
{
	command_t command;
	rig_cmd_photodiode_t photodiode[] = {{400, 400, 0}, {400, 500, 0}, {1024, 100, 0}, {0, 0, 0}, {600, 400, 3}};
	for (size_t i = 0; i < sizeof photodiode / sizeof photodiode[0]; i++)
		CHECK_EQ(parse(RIG_CMD_PHOTODIODE, &photodiode[i], sizeof photodiode[i], &command), RIG_STATUS_BAD_VALUE);
	rig_cmd_encoder_t encoder = {RIG_ENCODER_MIN_REPORT_TICKS - 1};
	CHECK_EQ(parse(RIG_CMD_ENCODER, &encoder, sizeof encoder, &command), RIG_STATUS_BAD_VALUE);
	rig_cmd_stream_t stream = {0x80};
	CHECK_EQ(parse(RIG_CMD_STREAM, &stream, sizeof stream, &command), RIG_STATUS_BAD_VALUE);
	rig_cmd_blink_t blinks[] = {
		{1000, 40000, 1, 8, 255},                        /* starts now: not ahead */
		{999, 40000, 1, 8, 255},                         /* in the past */
		{2000, RIG_BLINK_MIN_BIT_TICKS - 1, 1, 8, 255},  /* bits too short */
		{2000, 40000, 0, 8, 255},                        /* seed 0 never changes */
		{2000, 40000, 1, 0, 255},                        /* no bits */
		{2000, 40000, 1, RIG_BLINK_MAX_BITS + 1, 255},   /* too many bits */
	};
	for (size_t i = 0; i < sizeof blinks / sizeof blinks[0]; i++)
		CHECK_EQ(parse(RIG_CMD_BLINK, &blinks[i], sizeof blinks[i], &command), RIG_STATUS_BAD_VALUE);
}

static void test_command_parser_blink_start_across_clock_wrap(void)
{
	command_t command;
	rig_cmd_blink_t blink = {0x100, 40000, 1, 8, 255};
	frame_t frame = command_frame(RIG_CMD_BLINK, &blink, sizeof blink);
	CHECK_EQ(command_parse(&frame, 0xFFFFFF00u, &command), RIG_STATUS_OK);
}

/* ---- blink code ---- */

static void test_blink_lfsr_has_maximal_period(void)
{
	uint16_t state = 1;
	uint32_t period = 0;
	do {
		blink_lfsr_next(&state);
		period++;
	} while (state != 1 && period < 70000);
	CHECK_EQ(period, 65535);
}

static void test_blink_plays_code_at_scheduled_ticks(void)
{
	rig_cmd_blink_t command = {0xFFFFF000u, 3000, 0xACE1, 20, 200};
	blink_t blink;
	blink_start(&blink, &command);
	CHECK(!blink_due(&blink, 0xFFFFEFFFu));
	CHECK_EQ(blink_wait(&blink, 0xFFFFEFFFu), 1);
	uint16_t lfsr = command.seed;
	for (uint16_t k = 0; k < command.bits; k++) {
		uint32_t start = command.start_tick + (uint32_t)k * command.bit_ticks;
		CHECK(!blink_due(&blink, start - 1));
		CHECK(blink_due(&blink, start));
		uint16_t bit;
		uint8_t level = blink_advance(&blink, &bit);
		CHECK_EQ(bit, k);
		CHECK_EQ(level, blink_lfsr_next(&lfsr) ? 200 : 0);
	}
	CHECK(blink_due(&blink, command.start_tick + 20u * command.bit_ticks));
	uint16_t bit;
	CHECK_EQ(blink_advance(&blink, &bit), 0);
	CHECK_EQ(bit, 20);
	CHECK(!blink.active);
	CHECK(!blink_due(&blink, 0));
}

int main(void)
{
	RUN(test_crc_check_value);
	RUN(test_crc_table_matches_bitwise_definition);
	RUN(test_crc_catches_every_single_bit_error);
	RUN(test_cobs_round_trips_edge_cases);
	RUN(test_cobs_round_trips_random_data);
	RUN(test_cobs_rejects_malformed_input);
	RUN(test_frame_round_trip);
	RUN(test_frame_rejects_payload_over_maximum);
	RUN(test_frame_with_any_corrupted_byte_is_rejected);
	RUN(test_frame_truncated_empty_and_oversize);
	RUN(test_frame_recovered_after_random_noise);
	RUN(test_queue_keeps_order_and_counts_overflow);
	RUN(test_queue_wraps_its_indices);
	RUN(test_quadrature_counts_both_directions);
	RUN(test_quadrature_reverses_mid_cycle);
	RUN(test_quadrature_invalid_transitions_keep_count);
	RUN(test_photodiode_first_sample_only_primes);
	RUN(test_photodiode_hysteresis_ignores_noise_inside_band);
	RUN(test_photodiode_interpolates_crossing_times);
	RUN(test_photodiode_crossing_across_tick_wrap);
	RUN(test_photodiode_passage_centroid_is_pulse_centre_despite_hysteresis);
	RUN(test_photodiode_passage_across_tick_wrap);
	RUN(test_photodiode_bump_below_rise_is_no_passage);
	RUN(test_photodiode_passage_under_way_at_start_is_not_reported);
	RUN(test_command_parser_accepts_valid_commands);
	RUN(test_command_parser_rejects_unknown_types_and_lengths);
	RUN(test_command_parser_rejects_out_of_range_values);
	RUN(test_command_parser_blink_start_across_clock_wrap);
	RUN(test_blink_lfsr_has_maximal_period);
	RUN(test_blink_plays_code_at_scheduled_ticks);
	printf("%d passed, %d failed\n", tests_passed, tests_failed);
	return tests_failed ? 1 : 0;
}
