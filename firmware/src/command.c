#include "command.h"

#include <stdbool.h>
#include <string.h>

/* Payload length of each command type, or -1 for a type that is not a command. */
static int8_t payload_length(uint8_t type)
{
	switch (type) {
	case RIG_CMD_IDENTIFY:
	case RIG_CMD_SYNC:
	case RIG_CMD_STATUS:
		return 0;
	case RIG_CMD_LED:
		return sizeof(rig_cmd_led_t);
	case RIG_CMD_BLINK:
		return sizeof(rig_cmd_blink_t);
	case RIG_CMD_ENCODER:
		return sizeof(rig_cmd_encoder_t);
	case RIG_CMD_PHOTODIODE:
		return sizeof(rig_cmd_photodiode_t);
	case RIG_CMD_STREAM:
		return sizeof(rig_cmd_stream_t);
	default:
		return -1;
	}
}

static bool values_valid(const command_t *command, uint32_t now)
{
	switch (command->type) {
	case RIG_CMD_BLINK: {
		const rig_cmd_blink_t *blink = &command->args.blink;
		uint32_t lead = blink->start_tick - now;
		return lead > 0 && lead <= RIG_BLINK_MAX_LEAD_TICKS &&
		       blink->bit_ticks >= RIG_BLINK_MIN_BIT_TICKS && blink->seed != 0 &&
		       blink->bits >= 1 && blink->bits <= RIG_BLINK_MAX_BITS;
	}
	case RIG_CMD_ENCODER:
		return command->args.encoder.report_ticks == 0 ||
		       command->args.encoder.report_ticks >= RIG_ENCODER_MIN_REPORT_TICKS;
	case RIG_CMD_PHOTODIODE: {
		const rig_cmd_photodiode_t *photodiode = &command->args.photodiode;
		return photodiode->rise >= 1 && photodiode->rise <= RIG_ADC_MAX &&
		       photodiode->fall < photodiode->rise &&
		       (photodiode->raw_every == 0 || photodiode->raw_every >= RIG_SAMPLES_MIN_EVERY);
	}
	case RIG_CMD_STREAM:
		return (command->args.stream.mask &
			~(RIG_STREAM_ENCODER | RIG_STREAM_PHOTODIODE | RIG_STREAM_SAMPLES)) == 0;
	default:
		return true;
	}
}

uint8_t command_parse(const frame_t *frame, uint32_t now, command_t *command)
{
	command->type = frame->type;
	command->seq = frame->seq;
	int8_t length = payload_length(frame->type);
	if (length < 0)
		return RIG_STATUS_UNKNOWN_COMMAND;
	if (frame->length != (uint8_t)length)
		return RIG_STATUS_BAD_LENGTH;
	memcpy(&command->args, frame->payload, (uint8_t)length);
	return values_valid(command, now) ? RIG_STATUS_OK : RIG_STATUS_BAD_VALUE;
}
