/* Parsing and checking of the host's commands (protocol.h); the main loop carries them out. */
#ifndef RIG_COMMAND_H
#define RIG_COMMAND_H

#include <stdint.h>

#include "frame.h"
#include "protocol.h"

typedef struct {
	uint8_t type;
	uint8_t seq;
	union {
		rig_cmd_led_t led;
		rig_cmd_blink_t blink;
		rig_cmd_encoder_t encoder;
		rig_cmd_photodiode_t photodiode;
		rig_cmd_stream_t stream;
	} args;
} command_t;

/* Checks a received frame as a command at board time `now` (a blink must start after it) and
 * fills `command`. Returns RIG_STATUS_OK, or the RIG_STATUS_* code to answer with. */
uint8_t command_parse(const frame_t *frame, uint32_t now, command_t *command);

#endif
