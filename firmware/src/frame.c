#include "frame.h"

#include <string.h>

#include "cobs.h"
#include "crc16.h"

uint8_t frame_encode(uint8_t type, uint8_t seq, const void *payload, uint8_t length, uint8_t *out)
{
	if (length > RIG_FRAME_MAX_PAYLOAD)
		return 0;
	uint8_t raw[FRAME_RAW_MAX];
	raw[0] = type;
	raw[1] = seq;
	if (length)
		memcpy(raw + RIG_FRAME_HEADER_BYTES, payload, length);
	uint8_t end = RIG_FRAME_HEADER_BYTES + length;
	uint16_t crc = crc16(raw, end);
	raw[end] = (uint8_t)crc;
	raw[end + 1] = (uint8_t)(crc >> 8);
	uint8_t encoded = (uint8_t)cobs_encode(raw, end + RIG_FRAME_CRC_BYTES, out);
	out[encoded] = RIG_FRAME_DELIMITER;
	return encoded + 1;
}

void frame_receiver_init(frame_receiver_t *receiver)
{
	receiver->length = 0;
	receiver->oversize = 0;
}

static frame_result_t frame_check(const uint8_t *encoded, uint8_t length, frame_t *frame)
{
	uint8_t raw[FRAME_RAW_MAX];
	int decoded = cobs_decode(encoded, length, raw, sizeof raw);
	if (decoded < 0)
		return FRAME_CORRUPT;
	if (decoded < RIG_FRAME_HEADER_BYTES + RIG_FRAME_CRC_BYTES)
		return FRAME_TRUNCATED;
	uint8_t end = (uint8_t)decoded - RIG_FRAME_CRC_BYTES;
	uint16_t sent = (uint16_t)(raw[end] | (raw[end + 1] << 8));
	if (crc16(raw, end) != sent)
		return FRAME_CORRUPT;
	frame->type = raw[0];
	frame->seq = raw[1];
	frame->length = end - RIG_FRAME_HEADER_BYTES;
	memcpy(frame->payload, raw + RIG_FRAME_HEADER_BYTES, frame->length);
	return FRAME_OK;
}

frame_result_t frame_receive(frame_receiver_t *receiver, uint8_t byte, frame_t *frame)
{
	if (byte != RIG_FRAME_DELIMITER) {
		if (receiver->length == sizeof receiver->buffer)
			receiver->oversize = 1;
		else
			receiver->buffer[receiver->length++] = byte;
		return FRAME_PENDING;
	}
	frame_result_t result;
	if (receiver->oversize)
		result = FRAME_OVERSIZE;
	else if (receiver->length == 0)
		result = FRAME_EMPTY;
	else
		result = frame_check(receiver->buffer, receiver->length, frame);
	frame_receiver_init(receiver);
	return result;
}
