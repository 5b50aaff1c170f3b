/*
 * The serial protocol between the rig's microcontroller and the host: the one definition.
 *
 * The firmware includes this file; the Python side (rig/board/protocol.py) parses it, through
 * the link rig/board/protocol.h that ships it in the rig package, and a test compiles it with the
 * host C compiler to check that both read the same values and payload layouts. Keep to the forms that parser understands: `#define RIG_NAME <integer or "string">`
 * and `typedef struct RIG_PACKED { <fixed-width fields> } rig_<cmd|msg>_<name>_t;`, where the
 * struct for message type RIG_MSG_FOO is rig_msg_foo_t (a type with no struct has no payload).
 *
 * Frame on the wire:  COBS( type:u8  seq:u8  payload[0..RIG_FRAME_MAX_PAYLOAD]  crc:u16le )  0x00
 *   - seq counts the sender's frames modulo 256, so the receiver can count lost frames;
 *   - crc is CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final xor) over
 *     type, seq and payload;
 *   - all multi-byte fields are little-endian; the structs below are packed.
 * A frame that fails COBS decoding or its CRC, is shorter than header + CRC, longer than the
 * maximum, or carries an unknown type is counted and skipped by the receiver; it is never fatal.
 *
 * Time on the board is a free-running count of RIG_TICK_HZ ticks since reset. Messages carry its
 * low 32 bits (`tick`, wrapping every 2^32 / RIG_TICK_HZ seconds); SYNC and STATUS also carry the
 * high 16 bits (`epoch`) so the host can place every 32-bit tick on the full 48-bit time line.
 */
#ifndef RIG_PROTOCOL_H
#define RIG_PROTOCOL_H

#include <stdint.h>

#define RIG_PACKED __attribute__((packed))

/* Identity. */
#define RIG_PROTOCOL_VERSION 1
#define RIG_FIRMWARE_VERSION_MAJOR 1
#define RIG_FIRMWARE_VERSION_MINOR 0
#define RIG_FIRMWARE_VERSION_PATCH 0
#define RIG_BOARD_NAME "rig-avr"

/* Link and clock. */
#define RIG_BAUD 500000
#define RIG_UART_BITS_PER_BYTE 10
#define RIG_TICK_HZ 2000000
#define RIG_HEARTBEAT_TICKS 1000000

/* Framing. */
#define RIG_FRAME_DELIMITER 0x00
#define RIG_FRAME_HEADER_BYTES 2
#define RIG_FRAME_CRC_BYTES 2
#define RIG_FRAME_MAX_PAYLOAD 32
#define RIG_FRAME_MAX_ENCODED 38
#define RIG_CRC16_POLY 0x1021
#define RIG_CRC16_INIT 0xFFFF

/* Commands, host to board. Each is answered by the message named in its comment. */
#define RIG_CMD_IDENTIFY 0x01   /* -> RIG_MSG_IDENTITY */
#define RIG_CMD_SYNC 0x02       /* -> RIG_MSG_SYNC, then RIG_MSG_SYNC_SENT */
#define RIG_CMD_STATUS 0x03     /* -> RIG_MSG_STATUS */
#define RIG_CMD_LED 0x10        /* -> RIG_MSG_ACK */
#define RIG_CMD_BLINK 0x11      /* -> RIG_MSG_ACK */
#define RIG_CMD_ENCODER 0x12    /* -> RIG_MSG_ACK */
#define RIG_CMD_PHOTODIODE 0x13 /* -> RIG_MSG_ACK */
#define RIG_CMD_STREAM 0x14     /* -> RIG_MSG_ACK */

/* Messages, board to host. */
#define RIG_MSG_ACK 0x80
#define RIG_MSG_IDENTITY 0x81
#define RIG_MSG_SYNC 0x82
#define RIG_MSG_STATUS 0x83
#define RIG_MSG_ENCODER 0x84
#define RIG_MSG_CROSSING 0x85
#define RIG_MSG_SAMPLE 0x86
#define RIG_MSG_LED 0x87
#define RIG_MSG_PASSAGE 0x88
#define RIG_MSG_SYNC_SENT 0x89

/* RIG_MSG_ACK.status */
#define RIG_STATUS_OK 0
#define RIG_STATUS_BAD_LENGTH 1
#define RIG_STATUS_BAD_VALUE 2
#define RIG_STATUS_UNKNOWN_COMMAND 3

/* RIG_CMD_STREAM.mask bits: which event streams the board sends. LED events are always sent. */
#define RIG_STREAM_ENCODER 0x01    /* RIG_MSG_ENCODER */
#define RIG_STREAM_PHOTODIODE 0x02 /* RIG_MSG_CROSSING and RIG_MSG_PASSAGE */
#define RIG_STREAM_SAMPLES 0x04    /* RIG_MSG_SAMPLE */

/* Limits checked by the board's command parser (RIG_STATUS_BAD_VALUE when outside). */
#define RIG_ADC_MAX 1023
#define RIG_ENCODER_MIN_REPORT_TICKS 1000
#define RIG_SAMPLES_MIN_EVERY 4
#define RIG_BLINK_MIN_BIT_TICKS 2000
#define RIG_BLINK_MAX_LEAD_TICKS 0x7FFFFFFF
#define RIG_BLINK_MAX_BITS 65534

/*
 * Blink code: bit k of a blink is the output bit of a 16-bit Galois LFSR after k + 1 steps from
 * `seed` (state = (state >> 1) ^ (RIG_BLINK_LFSR_TAPS if the bit shifted out was 1)); the output
 * bit is the bit shifted out. The taps give the maximal period 65535.
 */
#define RIG_BLINK_LFSR_TAPS 0xB400
/* RIG_MSG_LED.bit for a change not made by a blink (RIG_CMD_LED, or the end of a blink). */
#define RIG_LED_MANUAL 0xFFFF

typedef struct RIG_PACKED {
	uint8_t level; /* 0 off, 255 fully on, in between PWM duty */
} rig_cmd_led_t;

typedef struct RIG_PACKED {
	uint32_t start_tick; /* board tick of bit 0; must lie ahead, by at most RIG_BLINK_MAX_LEAD_TICKS */
	uint32_t bit_ticks;  /* duration of one bit, at least RIG_BLINK_MIN_BIT_TICKS */
	uint16_t seed;       /* LFSR seed, not 0 */
	uint16_t bits;       /* number of bits, 1..RIG_BLINK_MAX_BITS; the LED goes off after the last */
	uint8_t level;       /* LED level for a 1 bit; a 0 bit is off */
} rig_cmd_blink_t;

typedef struct RIG_PACKED {
	uint32_t report_ticks; /* 0: one RIG_MSG_ENCODER per edge; else one per period with edges */
} rig_cmd_encoder_t;

typedef struct RIG_PACKED {
	uint16_t rise;      /* a crossing upwards when the signal reaches rise, 1..RIG_ADC_MAX */
	uint16_t fall;      /* and downwards when it drops to fall, below rise (the hysteresis) */
	uint16_t raw_every; /* send every n-th ADC sample as RIG_MSG_SAMPLE; 0 none */
} rig_cmd_photodiode_t;

typedef struct RIG_PACKED {
	uint8_t mask; /* RIG_STREAM_* bits */
} rig_cmd_stream_t;

typedef struct RIG_PACKED {
	uint8_t reply_to; /* seq of the command */
	uint8_t command;  /* its type */
	uint8_t status;   /* RIG_STATUS_* */
} rig_msg_ack_t;

typedef struct RIG_PACKED {
	uint8_t reply_to;
	uint8_t protocol;
	uint8_t firmware_major;
	uint8_t firmware_minor;
	uint8_t firmware_patch;
	uint32_t tick_hz;
	uint32_t cpu_hz;
	char name[8];
} rig_msg_identity_t;

typedef struct RIG_PACKED {
	uint8_t reply_to;
	uint16_t epoch;   /* high 16 bits of the 48-bit time at rx_tick */
	uint32_t rx_tick; /* when the command's final delimiter byte arrived */
} rig_msg_sync_t;

typedef struct RIG_PACKED {
	uint8_t reply_to; /* the RIG_CMD_SYNC answered by the RIG_MSG_SYNC just sent */
	uint32_t tx_tick; /* when the last byte of that RIG_MSG_SYNC went into the UART */
} rig_msg_sync_sent_t;

typedef struct RIG_PACKED {
	uint8_t reply_to;    /* seq of the RIG_CMD_STATUS, or 0 in a heartbeat */
	uint8_t unsolicited; /* 1 in the heartbeat sent every RIG_HEARTBEAT_TICKS */
	uint16_t epoch;
	uint32_t tick;
	uint8_t stream;          /* RIG_STREAM_* bits in force */
	uint16_t rx_frames;      /* good frames received (all counters wrap at 2^16) */
	uint16_t rx_corrupt;     /* frames failing COBS or CRC, too short or too long */
	uint16_t rx_unknown;     /* frames with an unknown command type */
	uint16_t rx_overflow;    /* bytes lost because the receive queue was full */
	uint16_t tx_dropped;     /* frames not sent because the transmit queue was full */
	uint16_t event_overflow; /* encoder edges or ADC samples lost from full queues */
	uint16_t quad_invalid;   /* encoder transitions that skipped a state */
} rig_msg_status_t;

typedef struct RIG_PACKED {
	uint32_t tick;  /* time of the latest edge */
	int32_t count;  /* quadrature count after it */
	uint16_t edges; /* edges since the previous RIG_MSG_ENCODER */
	int8_t step;    /* +1 or -1: the latest edge went from count - step to count */
} rig_msg_encoder_t;

typedef struct RIG_PACKED {
	uint32_t tick;  /* interpolated time the photodiode signal crossed the threshold */
	uint8_t rising; /* 1 upwards through rise, 0 downwards through fall */
} rig_msg_crossing_t;

/*
 * One passage of a bright object over the photodiode: the samples from the first above `fall`
 * to the next at or below it, with a rise to `rise` in between. centroid_tick is their time
 * centroid weighted by (sample - fall): for a symmetric brightness profile, the moment the object
 * was centred on the photodiode, unbiased by the hysteresis.
 */
typedef struct RIG_PACKED {
	uint32_t start_tick;
	uint32_t centroid_tick;
	uint32_t end_tick;
	uint16_t peak; /* highest sample */
} rig_msg_passage_t;

typedef struct RIG_PACKED {
	uint32_t tick;  /* sample-and-hold time of the ADC conversion */
	uint16_t value; /* 0..RIG_ADC_MAX */
} rig_msg_sample_t;

typedef struct RIG_PACKED {
	uint32_t tick; /* when the LED output changed */
	uint8_t level; /* new level */
	uint16_t bit;  /* blink bit index (bits for the switch-off after the last), or RIG_LED_MANUAL */
} rig_msg_led_t;

#endif
