/*
 * Rig microcontroller firmware (ATmega328P, 16 MHz): board clock, LED, pivot encoder, photodiode
 * and the host link. Pins and clocks are in board.h, the protocol in protocol.h.
 *
 * Interrupt handlers only take a timestamp and queue what they saw; decoding, framing and every
 * decision happen in the main loop, which sleeps whenever its queues are empty.
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <stdbool.h>
#include <string.h>
#include <util/atomic.h>

#include "blink.h"
#include "board.h"
#include "command.h"
#include "frame.h"
#include "photodiode.h"
#include "protocol.h"
#include "quadrature.h"
#include "queue.h"

_Static_assert(BOARD_CPU_HZ / BOARD_TIMER1_PRESCALE == RIG_TICK_HZ, "timer 1 must tick at RIG_TICK_HZ");
_Static_assert(BOARD_CPU_HZ % (16UL * RIG_BAUD) == 0, "RIG_BAUD must divide the CPU clock exactly");
_Static_assert(BOARD_TIMER1_PRESCALE == 8, "clock_start selects CPU / 8 for timer 1");
_Static_assert(BOARD_ADC_PRESCALE == 128, "hardware_init selects CPU / 128 for the ADC");

#define UBRR_VALUE (BOARD_CPU_HZ / (16UL * RIG_BAUD) - 1)
#define ADC_SAMPLE_LEAD_TICKS \
	(BOARD_ADC_SAMPLE_LEAD_HALF_CLOCKS * BOARD_ADC_PRESCALE / 2 / BOARD_TIMER1_PRESCALE)
/* A blink change closer than this is waited for awake. Further ones are waited for asleep: the
 * ADC's interrupt wakes the main loop every 104 us (CPU / 128 / 13), well within it. */
#define BLINK_AWAKE_TICKS 256
/* Thresholds until the host sets its own: the middle of the ADC range. */
#define DEFAULT_RISE 544
#define DEFAULT_FALL 480

typedef struct {
	uint32_t tick;
	uint8_t pins;
} edge_t;

typedef struct {
	uint32_t tick;
	uint16_t value;
} sample_t;

QUEUE_DEFINE(edge_queue, edge_t, 16)
QUEUE_DEFINE(sample_queue, sample_t, 16)
QUEUE_DEFINE(rx_queue, uint8_t, 64)
QUEUE_DEFINE(tick_queue, uint32_t, 8)
QUEUE_DEFINE(tx_queue, uint8_t, 128)

static edge_queue_t edges;
static sample_queue_t samples;
static rx_queue_t rx_bytes;
static tick_queue_t rx_delimiters; /* arrival tick of each delimiter in rx_bytes */
static tx_queue_t tx_bytes;
static volatile uint32_t timer1_overflows;

/* The last byte of a SYNC reply in tx_bytes, and when it went out (stamped by the UART handler). */
static volatile uint8_t sync_marker;
static volatile uint8_t sync_armed;
static volatile uint8_t sync_stamped;
static volatile uint32_t sync_sent_tick;
static uint8_t sync_reply_to;

static quadrature_t encoder;
static photodiode_t photodiode;
static blink_t blink;
static frame_receiver_t receiver;

static struct {
	uint8_t tx_seq;
	uint8_t stream;
	uint8_t led_level;
	uint32_t encoder_report_ticks;
	uint32_t next_encoder_report;
	uint16_t pending_edges;
	uint32_t last_edge_tick;
	int8_t last_step;
	uint16_t raw_every;
	uint16_t raw_countdown;
	uint32_t next_heartbeat;
	uint16_t rx_frames;
	uint16_t rx_corrupt;
	uint16_t rx_unknown;
	uint16_t tx_dropped;
} app;

/* Starts the board clock a few cycles after reset, before the C runtime's own start-up. */
static void clock_start(void) __attribute__((naked, used, section(".init3")));
static void clock_start(void)
{
	TCCR1B = _BV(CS11);
}

/* The low 32 bits of the 48-bit board time, and its high 16 bits in *epoch (if not NULL).
 * Interrupts must be off: an overflow not yet counted by its handler is added here. */
static uint32_t clock_read(uint16_t *epoch)
{
	uint16_t count = TCNT1;
	uint32_t overflows = timer1_overflows;
	if ((TIFR1 & _BV(TOV1)) && count < 0x8000)
		overflows++;
	if (epoch)
		*epoch = (uint16_t)(overflows >> 16);
	return (overflows << 16) | count;
}

static uint32_t clock_now(uint16_t *epoch)
{
	uint32_t tick;
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE)
	{
		tick = clock_read(epoch);
	}
	return tick;
}

ISR(TIMER1_OVF_vect)
{
	timer1_overflows++;
}

ISR(INT0_vect)
{
	edge_t edge = {clock_read(NULL), PIND};
	edge_queue_push(&edges, edge);
}

ISR(INT1_vect, ISR_ALIASOF(INT0_vect));

ISR(ADC_vect)
{
	sample_t sample = {clock_read(NULL) - ADC_SAMPLE_LEAD_TICKS, ADC};
	sample_queue_push(&samples, sample);
}

ISR(USART_RX_vect)
{
	uint32_t tick = clock_read(NULL);
	uint8_t status = UCSR0A;
	uint8_t byte = UDR0;
	if (status & _BV(DOR0))
		rx_bytes.overflow++;
	if (byte == RIG_FRAME_DELIMITER) {
		/* A delimiter without its tick would shift every later frame's tick: drop both. */
		if (tick_queue_free(&rx_delimiters) == 0 || rx_queue_free(&rx_bytes) == 0) {
			rx_bytes.overflow++;
			return;
		}
		tick_queue_push(&rx_delimiters, tick);
	}
	rx_queue_push(&rx_bytes, byte);
}

ISR(USART_UDRE_vect)
{
	uint8_t at = tx_bytes.tail;
	uint8_t byte;
	if (!tx_queue_pop(&tx_bytes, &byte)) {
		UCSR0B &= ~_BV(UDRIE0);
		return;
	}
	UDR0 = byte;
	if (sync_armed && at == sync_marker) {
		sync_sent_tick = clock_read(NULL);
		sync_armed = 0;
		sync_stamped = 1;
	}
}

/* Queues a whole frame for sending, or drops and counts it when it does not fit. The sequence
 * number advances either way, so the host sees the gap. With mark_end, the UART handler notes
 * when the frame's last byte goes out (for SYNC). */
static bool send_frame_marked(uint8_t type, const void *payload, uint8_t length, bool mark_end)
{
	uint8_t encoded[RIG_FRAME_MAX_ENCODED];
	uint8_t size = frame_encode(type, app.tx_seq++, payload, length, encoded);
	if (tx_queue_free(&tx_bytes) < size) {
		app.tx_dropped++;
		return false;
	}
	for (uint8_t i = 0; i < size; i++)
		tx_queue_push(&tx_bytes, encoded[i]);
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE)
	{
		if (mark_end) {
			sync_marker = (uint8_t)(tx_bytes.head - 1);
			sync_armed = 1;
			sync_stamped = 0;
		}
		UCSR0B |= _BV(UDRIE0);
	}
	return true;
}

static bool send_frame(uint8_t type, const void *payload, uint8_t length)
{
	return send_frame_marked(type, payload, length, false);
}

static void send_ack(const command_t *command, uint8_t status)
{
	rig_msg_ack_t ack = {command->seq, command->type, status};
	send_frame(RIG_MSG_ACK, &ack, sizeof ack);
}

static void send_identity(uint8_t reply_to)
{
	rig_msg_identity_t identity = {
		.reply_to = reply_to,
		.protocol = RIG_PROTOCOL_VERSION,
		.firmware_major = RIG_FIRMWARE_VERSION_MAJOR,
		.firmware_minor = RIG_FIRMWARE_VERSION_MINOR,
		.firmware_patch = RIG_FIRMWARE_VERSION_PATCH,
		.tick_hz = RIG_TICK_HZ,
		.cpu_hz = BOARD_CPU_HZ,
	};
	strncpy(identity.name, RIG_BOARD_NAME, sizeof identity.name);
	send_frame(RIG_MSG_IDENTITY, &identity, sizeof identity);
}

static void send_sync(uint8_t reply_to, uint32_t rx_tick)
{
	uint16_t epoch;
	uint32_t now = clock_now(&epoch);
	/* rx_tick lies before now; if the low 32 bits wrapped in between, it is one epoch back. */
	rig_msg_sync_t sync = {.reply_to = reply_to, .epoch = rx_tick > now ? epoch - 1 : epoch, .rx_tick = rx_tick};
	if (send_frame_marked(RIG_MSG_SYNC, &sync, sizeof sync, true))
		sync_reply_to = reply_to;
}

/* Once the SYNC reply has gone out, tells the host when. */
static void run_sync_sent(void)
{
	rig_msg_sync_sent_t sent = {.reply_to = sync_reply_to};
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE)
	{
		if (!sync_stamped)
			return;
		sync_stamped = 0;
		sent.tx_tick = sync_sent_tick;
	}
	send_frame(RIG_MSG_SYNC_SENT, &sent, sizeof sent);
}

static void send_status(uint8_t reply_to, uint8_t unsolicited)
{
	uint16_t epoch;
	rig_msg_status_t status = {
		.reply_to = reply_to,
		.unsolicited = unsolicited,
		.stream = app.stream,
		.rx_frames = app.rx_frames,
		.rx_corrupt = app.rx_corrupt,
		.rx_unknown = app.rx_unknown,
		.tx_dropped = app.tx_dropped,
		.quad_invalid = encoder.invalid,
	};
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE)
	{
		status.rx_overflow = rx_bytes.overflow;
		status.event_overflow = edges.overflow + samples.overflow;
	}
	status.tick = clock_now(&epoch);
	status.epoch = epoch;
	send_frame(RIG_MSG_STATUS, &status, sizeof status);
}

static void led_apply(uint8_t level, uint16_t bit)
{
	if (level == app.led_level)
		return;
	rig_msg_led_t change = {0, level, bit};
	/* The pin is set and the clock read with interrupts held off: a handler run in between would
	 * date the change late by as long as it took (up to about 10 us). */
	ATOMIC_BLOCK(ATOMIC_RESTORESTATE)
	{
		if (level == 0 || level == 255) {
			TCCR0A &= ~_BV(COM0A1);
			if (level)
				PORTD |= _BV(BOARD_LED_BIT);
			else
				PORTD &= ~_BV(BOARD_LED_BIT);
		} else {
			OCR0A = level;
			TCCR0A |= _BV(COM0A1);
		}
		change.tick = clock_read(NULL);
	}
	app.led_level = level;
	send_frame(RIG_MSG_LED, &change, sizeof change);
}

static void report_encoder(void)
{
	if (!(app.stream & RIG_STREAM_ENCODER)) {
		app.pending_edges = 0;
		return;
	}
	rig_msg_encoder_t report = {app.last_edge_tick, encoder.count, app.pending_edges, app.last_step};
	if (send_frame(RIG_MSG_ENCODER, &report, sizeof report))
		app.pending_edges = 0;
}

static void execute(const frame_t *frame, uint32_t rx_tick)
{
	command_t command;
	uint32_t now = clock_now(NULL);
	uint8_t status = command_parse(frame, now, &command);
	if (status == RIG_STATUS_UNKNOWN_COMMAND)
		app.rx_unknown++;
	if (status != RIG_STATUS_OK) {
		send_ack(&command, status);
		return;
	}
	switch (command.type) {
	case RIG_CMD_IDENTIFY:
		send_identity(command.seq);
		return;
	case RIG_CMD_SYNC:
		send_sync(command.seq, rx_tick);
		return;
	case RIG_CMD_STATUS:
		send_status(command.seq, 0);
		return;
	case RIG_CMD_LED:
		blink.active = false;
		led_apply(command.args.led.level, RIG_LED_MANUAL);
		break;
	case RIG_CMD_BLINK:
		blink_start(&blink, &command.args.blink);
		break;
	case RIG_CMD_ENCODER:
		app.encoder_report_ticks = command.args.encoder.report_ticks;
		app.next_encoder_report = now + app.encoder_report_ticks;
		break;
	case RIG_CMD_PHOTODIODE:
		photodiode_init(&photodiode, command.args.photodiode.rise, command.args.photodiode.fall);
		app.raw_every = command.args.photodiode.raw_every;
		app.raw_countdown = app.raw_every;
		break;
	case RIG_CMD_STREAM:
		app.stream = command.args.stream.mask;
		break;
	}
	send_ack(&command, RIG_STATUS_OK);
}

static bool run_receiver(void)
{
	static frame_t frame;
	bool worked = false;
	uint8_t byte;
	while (rx_queue_pop(&rx_bytes, &byte)) {
		worked = true;
		frame_result_t result = frame_receive(&receiver, byte, &frame);
		if (result == FRAME_PENDING)
			continue;
		uint32_t rx_tick = 0;
		tick_queue_pop(&rx_delimiters, &rx_tick);
		if (result == FRAME_OK) {
			app.rx_frames++;
			execute(&frame, rx_tick);
		} else if (result != FRAME_EMPTY) {
			app.rx_corrupt++;
		}
	}
	return worked;
}

static uint8_t encoder_pins(uint8_t port)
{
	return (uint8_t)((((port >> BOARD_ENCODER_A_BIT) & 1) << 1) | ((port >> BOARD_ENCODER_B_BIT) & 1));
}

static bool run_encoder(void)
{
	bool worked = false;
	edge_t edge;
	while (edge_queue_pop(&edges, &edge)) {
		worked = true;
		int8_t step = quadrature_update(&encoder, encoder_pins(edge.pins));
		if (step != 1 && step != -1)
			continue;
		app.pending_edges++;
		app.last_edge_tick = edge.tick;
		app.last_step = step;
		if (app.encoder_report_ticks == 0)
			report_encoder();
	}
	if (app.encoder_report_ticks != 0) {
		uint32_t now = clock_now(NULL);
		if ((int32_t)(now - app.next_encoder_report) >= 0) {
			if (app.pending_edges)
				report_encoder();
			app.next_encoder_report = now + app.encoder_report_ticks;
		}
	}
	return worked;
}

static bool run_photodiode(void)
{
	bool worked = false;
	sample_t sample;
	while (sample_queue_pop(&samples, &sample)) {
		worked = true;
		photodiode_event_t event;
		photodiode_update(&photodiode, sample.value, sample.tick, &event);
		if (event.crossing && (app.stream & RIG_STREAM_PHOTODIODE)) {
			rig_msg_crossing_t message = {event.crossing_tick, event.crossing > 0};
			send_frame(RIG_MSG_CROSSING, &message, sizeof message);
		}
		if (event.passage && (app.stream & RIG_STREAM_PHOTODIODE)) {
			rig_msg_passage_t message = {event.start_tick, event.centroid_tick, event.end_tick, event.peak};
			send_frame(RIG_MSG_PASSAGE, &message, sizeof message);
		}
		if (app.raw_every && (app.stream & RIG_STREAM_SAMPLES) && --app.raw_countdown == 0) {
			app.raw_countdown = app.raw_every;
			rig_msg_sample_t message = {sample.tick, sample.value};
			send_frame(RIG_MSG_SAMPLE, &message, sizeof message);
		}
	}
	return worked;
}

/* Plays the blink change that is due; returns whether to stay awake for the next. */
static bool run_blink(void)
{
	if (!blink.active)
		return false;
	uint32_t wait = blink_wait(&blink, clock_now(NULL));
	if (wait == 0) {
		uint16_t bit;
		uint8_t level = blink_advance(&blink, &bit);
		led_apply(level, bit);
		return true;
	}
	return wait < BLINK_AWAKE_TICKS;
}

static void run_heartbeat(void)
{
	uint32_t now = clock_now(NULL);
	if ((int32_t)(now - app.next_heartbeat) >= 0) {
		app.next_heartbeat = now + RIG_HEARTBEAT_TICKS;
		send_status(0, 1);
	}
}

static void sleep_until_interrupt(void)
{
	cli();
	if (rx_queue_empty(&rx_bytes) && edge_queue_empty(&edges) && sample_queue_empty(&samples)) {
		sleep_enable();
		sei();
		sleep_cpu();
		sleep_disable();
	}
	sei();
}

static void hardware_init(void)
{
	DDRD |= _BV(BOARD_LED_BIT);
	DDRD &= ~(_BV(BOARD_ENCODER_A_BIT) | _BV(BOARD_ENCODER_B_BIT));
	PORTD |= _BV(BOARD_ENCODER_A_BIT) | _BV(BOARD_ENCODER_B_BIT);

	/* Timer 0: fast PWM at CPU / 64 / 256 (977 Hz) for the LED; connected only for mid levels. */
	TCCR0A = _BV(WGM01) | _BV(WGM00);
	TCCR0B = _BV(CS01) | _BV(CS00);

	/* Timer 1 runs since clock_start; count its overflows. */
	TIMSK1 = _BV(TOIE1);

	/* Encoder A and B: an interrupt on every change of either. */
	EICRA = _BV(ISC00) | _BV(ISC10);
	EIFR = _BV(INTF0) | _BV(INTF1);
	EIMSK = _BV(INT0) | _BV(INT1);

	UBRR0 = UBRR_VALUE;
	UCSR0A = 0;
	UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
	UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
	while (UCSR0A & _BV(RXC0))
		(void)UDR0;

	/* Photodiode: AVcc reference, free-running conversions at CPU / 128 / 13 (9.6 kHz). */
	ADMUX = _BV(REFS0) | BOARD_PHOTODIODE_CHANNEL;
	DIDR0 = _BV(BOARD_PHOTODIODE_CHANNEL);
	ADCSRB = 0;
	ADCSRA = _BV(ADEN) | _BV(ADATE) | _BV(ADIE) | _BV(ADSC) | _BV(ADPS2) | _BV(ADPS1) | _BV(ADPS0);

	set_sleep_mode(SLEEP_MODE_IDLE);
}

int main(void)
{
	hardware_init();
	quadrature_init(&encoder, encoder_pins(PIND));
	photodiode_init(&photodiode, DEFAULT_RISE, DEFAULT_FALL);
	frame_receiver_init(&receiver);
	app.next_heartbeat = clock_now(NULL) + RIG_HEARTBEAT_TICKS;
	sei();
	for (;;) {
		bool busy = run_receiver();
		busy |= run_encoder();
		busy |= run_photodiode();
		busy |= run_blink();
		run_sync_sent();
		run_heartbeat();
		if (!busy)
			sleep_until_interrupt();
	}
}
