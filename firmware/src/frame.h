/* Rig protocol frames: type, seq, payload and CRC, COBS-encoded and ended by 0x00 (protocol.h). */
#ifndef RIG_FRAME_H
#define RIG_FRAME_H

#include <stdint.h>

#include "protocol.h"

#define FRAME_RAW_MAX (RIG_FRAME_HEADER_BYTES + RIG_FRAME_MAX_PAYLOAD + RIG_FRAME_CRC_BYTES)

typedef struct {
	uint8_t type;
	uint8_t seq;
	uint8_t length;
	uint8_t payload[RIG_FRAME_MAX_PAYLOAD];
} frame_t;

/* Encodes a frame, delimiter included, into `out` (RIG_FRAME_MAX_ENCODED bytes); returns its
 * length, or 0 when the payload is longer than RIG_FRAME_MAX_PAYLOAD. */
uint8_t frame_encode(uint8_t type, uint8_t seq, const void *payload, uint8_t length, uint8_t *out);

typedef enum {
	FRAME_PENDING,   /* byte stored; no delimiter yet */
	FRAME_OK,        /* a good frame is in the output */
	FRAME_EMPTY,     /* a delimiter with nothing before it: idle line, not an error */
	FRAME_CORRUPT,   /* bad COBS or CRC */
	FRAME_TRUNCATED, /* too short to hold header and CRC */
	FRAME_OVERSIZE,  /* longer than RIG_FRAME_MAX_ENCODED; skipped up to its delimiter */
} frame_result_t;

/* Collects bytes from the line until a delimiter, then checks and decodes the frame. */
typedef struct {
	uint8_t buffer[RIG_FRAME_MAX_ENCODED - 1];
	uint8_t length;
	uint8_t oversize;
} frame_receiver_t;

void frame_receiver_init(frame_receiver_t *receiver);
frame_result_t frame_receive(frame_receiver_t *receiver, uint8_t byte, frame_t *frame);

#endif
