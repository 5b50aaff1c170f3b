/*
 * The rig board, emulated: runs the real firmware ELF on simavr's ATmega328P at 16 MHz, in step
 * with the wall clock, and wires it to a scripted world.
 *
 *   UART0       a pseudo-terminal (pty_link.c); its path is printed on stdout as
 *               "rig-board-sim: pty PATH" and, with --link, kept behind a symlink
 *   clock       emulated time runs with the wall clock, at most 0.15 ms ahead: "rig-board-sim:
 *               emulated time 0 is CLOCK_MONOTONIC S s" is printed before the pty; when the machine
 *               keeps the emulation from running for over a millisecond, the board's time stands
 *               still for that long (it does not race to catch up)
 *   encoder     quadrature edges on the encoder pins from a scripted pendulum
 *                 angle(t) = amplitude * exp(-t / decay) * cos(2 pi t / period + phase)
 *               (no decay when decay is 0), counts = round(angle / (2 pi / counts-per-rev))
 *   photodiode  the ADC input sees a scripted display showing the pendulum `display-delay` late:
 *                 mV(t) = dark + (bright - dark) * exp(-(angle(t - delay) - photodiode-angle)^2
 *                                                       / (2 spot-width^2)) + noise
 *               sampled, as on the chip, 1.5 ADC clocks after each conversion starts
 *   LED         every change of the LED pin and of its PWM duty, logged with --led-log
 *   faults      --noise-at S: a burst of random bytes into both directions of the serial line at
 *               emulated time S; --drop-at S: the serial port hangs up at S (the host sees an I/O
 *               error) and a new pty appears behind the --link symlink
 *
 * Emulated time t = CPU cycle / 16 MHz from reset; the firmware starts its clock within 1 us of
 * it. The run ends at --duration seconds of emulated time, on SIGTERM or on SIGINT.
 *
 * simavr's own uart_pty part (Debian's 1.6) is not used: its thread blocks writing to a host
 * that stops reading, copies garbage into the UART after a failed read, and its stop can hang;
 * pty_link does the same job from the emulation's thread without blocking.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <getopt.h>
#include <libgen.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <time.h>
#include <unistd.h>

#include "avr_adc.h"
#include "avr_ioport.h"
#include "avr_timer.h"
#include "avr_uart.h"
#include "sim_avr.h"
#include "sim_elf.h"
#include "sim_irq.h"

#include "board.h"
#include "pty_link.h"

#define MAX_EVENTS 16
/* How often the emulation is held back to the wall clock (50 us), and how far ahead of it it may
 * run before it sleeps (each sleep is a system call: fewer, longer sleeps leave more CPU). */
#define PACE_CYCLES 800
#define PACE_AHEAD_NS 100000
/* A lag shorter than this (a late wake-up) is caught up by running fast for a moment; a longer
 * one (the machine was busy elsewhere) is not: the board's time stood still instead. */
#define PACE_BEHIND_NS 1000000
/* How often the serial port is polled: 50 us. */
#define LINK_POLL_CYCLES 800
/* Farthest the encoder looks ahead for its next edge before checking again. */
#define ENCODER_HORIZON_S 0.05

typedef struct {
	double amplitude;
	double period;
	double phase;
	double decay;
	long counts_per_rev;
} pendulum_t;

typedef struct {
	double delay;
	double angle;
	double width;
	double dark_mv;
	double bright_mv;
	double noise_mv;
} display_t;

typedef struct {
	double times[MAX_EVENTS];
	int count;
	int next;
} schedule_t;

typedef struct {
	const char *firmware;
	const char *link;
	const char *led_log;
	double duration;
	unsigned long long seed;
	int noise_bytes;
	pendulum_t pendulum;
	display_t display;
	schedule_t noise;
	schedule_t drops;
} options_t;

typedef struct {
	avr_t *avr;
	options_t options;
	pty_link_t link;
	uint8_t received[64];
	size_t received_start;
	size_t received_length;
	avr_irq_t *uart_input;
	int uart_full;
	avr_irq_t *encoder_a;
	avr_irq_t *encoder_b;
	uint8_t encoder_ab; /* the levels the encoder drives on A and B */
	long encoder_count;
	avr_cycle_count_t encoder_step;
	avr_irq_t *adc_input;
	FILE *led_log;
	int led_pin; /* last level logged, -1 before the first */
	int64_t origin_ns;    /* CLOCK_MONOTONIC of emulated time 0, moved on by stalls */
	int64_t stalled_ns;   /* all the time the emulation stood still */
	int64_t wake_late_ns; /* running mean of how late a pacing sleep wakes */
	uint64_t random;
} board_t;

static volatile sig_atomic_t stop_requested;

static void on_signal(int signal_number)
{
	(void)signal_number;
	stop_requested = 1;
}

static void fail(const char *message, const char *detail)
{
	fprintf(stderr, "rig-board-sim: %s%s%s\n", message, detail ? ": " : "", detail ? detail : "");
	exit(2);
}

static uint64_t random_next(board_t *board)
{
	board->random ^= board->random << 13;
	board->random ^= board->random >> 7;
	board->random ^= board->random << 17;
	return board->random;
}

static double random_normal(board_t *board)
{
	double u1 = ((random_next(board) >> 11) + 1.0) / 9007199254740993.0;
	double u2 = (random_next(board) >> 11) / 9007199254740992.0;
	return sqrt(-2.0 * log(u1)) * cos(2.0 * M_PI * u2);
}

static double cycle_seconds(const board_t *board, avr_cycle_count_t cycle)
{
	return (double)cycle / board->avr->frequency;
}

static double pendulum_angle(const pendulum_t *pendulum, double t)
{
	double envelope = pendulum->decay > 0 ? exp(-t / pendulum->decay) : 1.0;
	return pendulum->amplitude * envelope * cos(2.0 * M_PI * t / pendulum->period + pendulum->phase);
}

static long pendulum_count(const pendulum_t *pendulum, double t)
{
	return lround(floor(pendulum_angle(pendulum, t) * pendulum->counts_per_rev / (2.0 * M_PI) + 0.5));
}

/* ---- encoder ---- */

static void encoder_drive(board_t *board, long count)
{
	static const uint8_t pins_of_phase[4] = {0, 2, 3, 1}; /* ab: 00, 10, 11, 01 counting up */
	uint8_t old_ab = board->encoder_ab;
	board->encoder_ab = pins_of_phase[((count % 4) + 4) % 4];
	board->encoder_count = count;
	/* simavr drives an input pin to its pull-up on every write of the port (the LED's, say) unless
	 * the pin has an "external" level: the encoder's, which wins over a pull-up. */
	uint8_t a = (board->encoder_ab >> 1) & 1;
	uint8_t b = board->encoder_ab & 1;
	avr_ioport_external_t external = {
		.name = BOARD_ENCODER_PORT,
		.mask = (1 << BOARD_ENCODER_A_BIT) | (1 << BOARD_ENCODER_B_BIT),
		.value = (a << BOARD_ENCODER_A_BIT) | (b << BOARD_ENCODER_B_BIT),
	};
	avr_ioctl(board->avr, AVR_IOCTL_IOPORT_SET_EXTERNAL(BOARD_ENCODER_PORT), &external);
	if ((old_ab ^ board->encoder_ab) & 2)
		avr_raise_irq(board->encoder_a, a);
	if ((old_ab ^ board->encoder_ab) & 1)
		avr_raise_irq(board->encoder_b, b);
}

/* The first cycle after `from` at which the scripted count differs from the one on the pins. */
static avr_cycle_count_t encoder_next_edge(board_t *board, avr_cycle_count_t from)
{
	const pendulum_t *pendulum = &board->options.pendulum;
	avr_cycle_count_t horizon = from + (avr_cycle_count_t)(ENCODER_HORIZON_S * board->avr->frequency);
	avr_cycle_count_t low = from;
	for (avr_cycle_count_t high = from + board->encoder_step; high <= horizon; high += board->encoder_step) {
		if (pendulum_count(pendulum, cycle_seconds(board, high)) == board->encoder_count) {
			low = high;
			continue;
		}
		while (high - low > 1) {
			avr_cycle_count_t middle = low + (high - low) / 2;
			if (pendulum_count(pendulum, cycle_seconds(board, middle)) == board->encoder_count)
				low = middle;
			else
				high = middle;
		}
		return high;
	}
	return horizon;
}

static avr_cycle_count_t encoder_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	board_t *board = param;
	long target = pendulum_count(&board->options.pendulum, cycle_seconds(board, avr->cycle));
	if (target != board->encoder_count) {
		encoder_drive(board, board->encoder_count + (target > board->encoder_count ? 1 : -1));
		if (target != board->encoder_count)
			return avr->cycle + 16; /* more than one count behind: one step at a time */
	}
	(void)when;
	return encoder_next_edge(board, avr->cycle);
}

/* ---- photodiode ---- */

static uint32_t photodiode_millivolts(board_t *board, double t)
{
	const display_t *display = &board->options.display;
	double offset = (pendulum_angle(&board->options.pendulum, t - display->delay) - display->angle) / display->width;
	double mv = display->dark_mv + (display->bright_mv - display->dark_mv) * exp(-0.5 * offset * offset);
	if (display->noise_mv > 0)
		mv += display->noise_mv * random_normal(board);
	if (mv < 0)
		mv = 0;
	if (mv > board->avr->avcc)
		mv = board->avr->avcc;
	return (uint32_t)lround(mv);
}

/* Called as each conversion starts, which in free-running mode is as the previous one ends and
 * the firmware is about to read it: give it the input at that conversion's sample-and-hold. */
static void on_adc_trigger(struct avr_irq_t *irq, uint32_t value, void *param)
{
	board_t *board = param;
	union {
		avr_adc_mux_t mux;
		uint32_t value;
	} trigger = {.value = value};
	(void)irq;
	if (trigger.mux.kind != ADC_MUX_SINGLE || trigger.mux.src != BOARD_PHOTODIODE_CHANNEL)
		return;
	avr_cycle_count_t lead = BOARD_ADC_SAMPLE_LEAD_HALF_CLOCKS * BOARD_ADC_PRESCALE / 2;
	double t = cycle_seconds(board, board->avr->cycle > lead ? board->avr->cycle - lead : 0);
	avr_raise_irq(board->adc_input, photodiode_millivolts(board, t));
}

/* ---- LED ---- */

static void log_led(board_t *board, const char *source, uint32_t value)
{
	if (board->led_log)
		fprintf(board->led_log, "%.9f,%s,%u\n", cycle_seconds(board, board->avr->cycle), source, value);
}

/* simavr raises the pin again on every write of its port: log only the changes. */
static void on_led_pin(struct avr_irq_t *irq, uint32_t value, void *param)
{
	board_t *board = param;
	(void)irq;
	if ((int)value != board->led_pin) {
		board->led_pin = (int)value;
		log_led(board, "pin", value);
	}
}

static void on_led_pwm(struct avr_irq_t *irq, uint32_t value, void *param)
{
	(void)irq;
	log_led(param, "pwm", value);
}

/* ---- serial line ---- */

static void on_board_byte(struct avr_irq_t *irq, uint32_t value, void *param)
{
	board_t *board = param;
	(void)irq;
	pty_link_send(&board->link, (uint8_t)value);
	/* A frame ends with 0x00: hand it over at once rather than at the next poll, since the host
	 * times the arrival of frames (clock sync). */
	if (value == 0)
		pty_link_flush(&board->link);
}

static void on_uart_xoff(struct avr_irq_t *irq, uint32_t value, void *param)
{
	board_t *board = param;
	(void)irq;
	board->uart_full = value != 0;
}

/* Passes the host's bytes to the UART while its receive queue has room, and the board's to
 * the host. */
static avr_cycle_count_t link_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	board_t *board = param;
	(void)avr;
	pty_link_flush(&board->link);
	if (board->received_length == 0) {
		board->received_start = 0;
		board->received_length = pty_link_receive(&board->link, board->received, sizeof board->received);
	}
	while (board->received_length && !board->uart_full) {
		avr_raise_irq(board->uart_input, board->received[board->received_start++]);
		board->received_length--;
	}
	return when + LINK_POLL_CYCLES;
}

static void announce_pty(board_t *board)
{
	const char *path = board->link.path;
	if (board->options.link) {
		char temporary[PATH_MAX];
		snprintf(temporary, sizeof temporary, "%s.%d", board->options.link, (int)getpid());
		unlink(temporary);
		if (symlink(path, temporary) != 0 || rename(temporary, board->options.link) != 0)
			fail("cannot make the link", strerror(errno));
	}
	printf("rig-board-sim: pty %s\n", path);
}

/* Hangs up the serial port, as an unplugged cable would, and opens a new one. */
static void drop_connection(board_t *board)
{
	pty_link_close(&board->link);
	board->received_length = 0;
	if (pty_link_open(&board->link) != 0)
		fail("cannot open a pseudo-terminal", strerror(errno));
	printf("rig-board-sim: dropped the connection at %.6f s\n", cycle_seconds(board, board->avr->cycle));
	announce_pty(board);
}

static void inject_noise(board_t *board)
{
	for (int i = 0; i < board->options.noise_bytes; i++)
		pty_link_send(&board->link, (uint8_t)random_next(board));
	for (int i = 0; i < board->options.noise_bytes && !board->uart_full; i++)
		avr_raise_irq(board->uart_input, (uint8_t)random_next(board));
	printf("rig-board-sim: noise at %.6f s\n", cycle_seconds(board, board->avr->cycle));
}

static avr_cycle_count_t schedule_next(board_t *board, schedule_t *schedule)
{
	if (schedule->next >= schedule->count)
		return 0;
	return (avr_cycle_count_t)(schedule->times[schedule->next] * board->avr->frequency) + 1;
}

static avr_cycle_count_t noise_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	board_t *board = param;
	(void)avr;
	(void)when;
	inject_noise(board);
	board->options.noise.next++;
	return schedule_next(board, &board->options.noise);
}

static avr_cycle_count_t drop_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	board_t *board = param;
	(void)avr;
	(void)when;
	drop_connection(board);
	board->options.drops.next++;
	return schedule_next(board, &board->options.drops);
}

/* ---- wall clock ---- */

static int64_t monotonic_ns(void)
{
	struct timespec now;
	clock_gettime(CLOCK_MONOTONIC, &now);
	return now.tv_sec * 1000000000LL + now.tv_nsec;
}

static avr_cycle_count_t pace_timer(avr_t *avr, avr_cycle_count_t when, void *param)
{
	board_t *board = param;
	int64_t emulated_ns = (int64_t)((double)avr->cycle * 1e9 / avr->frequency);
	int64_t ahead_ns = board->origin_ns + emulated_ns - monotonic_ns();
	if (ahead_ns > PACE_AHEAD_NS) {
		/* Wake when the wall clock reaches the emulated time: ask that early by the usual lateness. */
		int64_t wanted = board->origin_ns + emulated_ns - board->wake_late_ns;
		struct timespec until = {wanted / 1000000000LL, wanted % 1000000000LL};
		while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &until, NULL) == EINTR && !stop_requested)
			;
		board->wake_late_ns += (monotonic_ns() - wanted - board->wake_late_ns) / 16;
	} else if (ahead_ns < -PACE_BEHIND_NS) {
		board->origin_ns -= ahead_ns;
		board->stalled_ns -= ahead_ns;
	}
	return when + PACE_CYCLES;
}

/* The AVR's sleep costs no wall time here: pace_timer keeps the emulation on the wall clock. */
static void skip_sleep(avr_t *avr, avr_cycle_count_t how_long)
{
	(void)avr;
	(void)how_long;
}

/* ---- options ---- */

static double parse_number(const char *text, const char *option)
{
	char *end;
	errno = 0;
	double value = strtod(text, &end);
	if (errno || end == text || *end || !isfinite(value))
		fail("not a number for", option);
	return value;
}

static void schedule_add(schedule_t *schedule, double t, const char *option)
{
	if (schedule->count == MAX_EVENTS)
		fail("too many times for", option);
	if (t < 0 || (schedule->count && t <= schedule->times[schedule->count - 1]))
		fail("times must be positive and increasing for", option);
	schedule->times[schedule->count++] = t;
}

static void usage(FILE *out)
{
	fprintf(out,
		"usage: rig_board_sim [--firmware ELF] [--link PATH] [--duration S] [--led-log CSV]\n"
		"       [--amplitude RAD] [--period S] [--phase RAD] [--decay S] [--counts-per-rev N]\n"
		"       [--display-delay S] [--photodiode-angle RAD] [--spot-width RAD]\n"
		"       [--dark-mv MV] [--bright-mv MV] [--adc-noise-mv MV] [--seed N]\n"
		"       [--noise-at S]... [--noise-bytes N] [--drop-at S]...\n");
}

static void parse_options(int argc, char **argv, options_t *options)
{
	static char default_firmware[PATH_MAX];
	char self[PATH_MAX];
	ssize_t length = readlink("/proc/self/exe", self, sizeof self - 1);
	if (length > 0) {
		self[length] = 0;
		snprintf(default_firmware, sizeof default_firmware, "%s/rig.elf", dirname(self));
	}
	*options = (options_t){
		.firmware = default_firmware,
		.seed = 1,
		.noise_bytes = 24,
		.pendulum = {.amplitude = 0.3, .period = 1.25, .counts_per_rev = 2400},
		.display = {.delay = 0.0125, .angle = 0.02, .width = 0.02, .dark_mv = 250, .bright_mv = 4000, .noise_mv = 5},
	};
	static const struct option long_options[] = {
		{"firmware", required_argument, 0, 'f'}, {"link", required_argument, 0, 'l'},
		{"duration", required_argument, 0, 'd'}, {"led-log", required_argument, 0, 'L'},
		{"amplitude", required_argument, 0, 'A'}, {"period", required_argument, 0, 'T'},
		{"phase", required_argument, 0, 'P'}, {"decay", required_argument, 0, 'D'},
		{"counts-per-rev", required_argument, 0, 'c'}, {"display-delay", required_argument, 0, 'y'},
		{"photodiode-angle", required_argument, 0, 'a'}, {"spot-width", required_argument, 0, 'w'},
		{"dark-mv", required_argument, 0, 'k'}, {"bright-mv", required_argument, 0, 'b'},
		{"adc-noise-mv", required_argument, 0, 'n'}, {"seed", required_argument, 0, 's'},
		{"noise-at", required_argument, 0, 'N'}, {"noise-bytes", required_argument, 0, 'B'},
		{"drop-at", required_argument, 0, 'X'}, {"help", no_argument, 0, 'h'}, {0, 0, 0, 0},
	};
	int option;
	while ((option = getopt_long(argc, argv, "", long_options, NULL)) != -1) {
		switch (option) {
		case 'f': options->firmware = optarg; break;
		case 'l': options->link = optarg; break;
		case 'L': options->led_log = optarg; break;
		case 'd': options->duration = parse_number(optarg, "--duration"); break;
		case 'A': options->pendulum.amplitude = parse_number(optarg, "--amplitude"); break;
		case 'T': options->pendulum.period = parse_number(optarg, "--period"); break;
		case 'P': options->pendulum.phase = parse_number(optarg, "--phase"); break;
		case 'D': options->pendulum.decay = parse_number(optarg, "--decay"); break;
		case 'c': options->pendulum.counts_per_rev = lround(parse_number(optarg, "--counts-per-rev")); break;
		case 'y': options->display.delay = parse_number(optarg, "--display-delay"); break;
		case 'a': options->display.angle = parse_number(optarg, "--photodiode-angle"); break;
		case 'w': options->display.width = parse_number(optarg, "--spot-width"); break;
		case 'k': options->display.dark_mv = parse_number(optarg, "--dark-mv"); break;
		case 'b': options->display.bright_mv = parse_number(optarg, "--bright-mv"); break;
		case 'n': options->display.noise_mv = parse_number(optarg, "--adc-noise-mv"); break;
		case 's': options->seed = (unsigned long long)parse_number(optarg, "--seed"); break;
		case 'N': schedule_add(&options->noise, parse_number(optarg, "--noise-at"), "--noise-at"); break;
		case 'B': options->noise_bytes = (int)parse_number(optarg, "--noise-bytes"); break;
		case 'X': schedule_add(&options->drops, parse_number(optarg, "--drop-at"), "--drop-at"); break;
		case 'h': usage(stdout); exit(0);
		default: usage(stderr); exit(2);
		}
	}
	if (optind != argc) {
		usage(stderr);
		exit(2);
	}
	if (options->pendulum.period <= 0 || options->pendulum.counts_per_rev < 4 || options->display.width <= 0 ||
	    options->duration < 0 || options->noise_bytes < 0 || options->noise_bytes > 64)
		fail("an option is out of range; see the header of rig_board_sim.c", NULL);
}

/* ---- set-up ---- */

static void connect_uart(board_t *board)
{
	avr_t *avr = board->avr;
	if (pty_link_open(&board->link) != 0)
		fail("cannot open a pseudo-terminal", strerror(errno));
	uint32_t flags = 0;
	avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
	flags &= ~(AVR_UART_FLAG_POLL_SLEEP | AVR_UART_FLAG_STDIO);
	avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
	avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), on_board_byte, board);
	board->uart_input = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);
	avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUT_XOFF), on_uart_xoff, board);
	avr_cycle_timer_register(avr, LINK_POLL_CYCLES, link_timer, board);
}

static void connect_world(board_t *board)
{
	avr_t *avr = board->avr;
	const pendulum_t *pendulum = &board->options.pendulum;
	board->encoder_a = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(BOARD_ENCODER_PORT), BOARD_ENCODER_A_BIT);
	board->encoder_b = avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(BOARD_ENCODER_PORT), BOARD_ENCODER_B_BIT);
	board->encoder_ab = 0; /* the pins start low */
	encoder_drive(board, pendulum_count(pendulum, 0));
	double max_speed = fabs(pendulum->amplitude) * 2.0 * M_PI / pendulum->period + 1e-9;
	double edge_interval = 2.0 * M_PI / pendulum->counts_per_rev / max_speed;
	board->encoder_step = (avr_cycle_count_t)fmax(16.0, edge_interval / 16.0 * avr->frequency);
	avr_cycle_timer_register(avr, 1, encoder_timer, board);

	board->led_pin = -1;
	board->adc_input = avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_ADC0 + BOARD_PHOTODIODE_CHANNEL);
	avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_ADC_GETIRQ, ADC_IRQ_OUT_TRIGGER), on_adc_trigger, board);

	if (board->options.led_log) {
		board->led_log = fopen(board->options.led_log, "w");
		if (!board->led_log)
			fail("cannot write the LED log", strerror(errno));
		setvbuf(board->led_log, NULL, _IOLBF, 0);
		fprintf(board->led_log, "time_s,source,value\n");
	}
	avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(BOARD_LED_PORT), BOARD_LED_BIT), on_led_pin, board);
	avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_TIMER_GETIRQ('0'), TIMER_IRQ_OUT_PWM0), on_led_pwm, board);

	avr_cycle_count_t first;
	if ((first = schedule_next(board, &board->options.noise)))
		avr_cycle_timer_register(avr, first, noise_timer, board);
	if ((first = schedule_next(board, &board->options.drops)))
		avr_cycle_timer_register(avr, first, drop_timer, board);
}

int main(int argc, char **argv)
{
	static board_t board;
	setvbuf(stdout, NULL, _IOLBF, 0);
	parse_options(argc, argv, &board.options);
	board.random = board.options.seed * 0x9E3779B97F4A7C15ULL + 1;

	struct sigaction action = {.sa_handler = on_signal};
	sigemptyset(&action.sa_mask);
	sigaction(SIGINT, &action, NULL);
	sigaction(SIGTERM, &action, NULL);
	prctl(PR_SET_TIMERSLACK, 1UL);

	elf_firmware_t firmware;
	memset(&firmware, 0, sizeof firmware);
	if (access(board.options.firmware, R_OK) != 0 || elf_read_firmware(board.options.firmware, &firmware) != 0)
		fail("cannot read the firmware (build it with `make -C firmware`)", board.options.firmware);
	board.avr = avr_make_mcu_by_name(BOARD_MCU);
	if (!board.avr)
		fail("simavr does not know the MCU", BOARD_MCU);
	avr_init(board.avr);
	avr_load_firmware(board.avr, &firmware);
	board.avr->frequency = BOARD_CPU_HZ;
	board.avr->vcc = board.avr->avcc = board.avr->aref = 5000;
	board.avr->sleep = skip_sleep;

	connect_world(&board);
	connect_uart(&board);
	avr_cycle_timer_register(board.avr, PACE_CYCLES, pace_timer, &board);
	board.origin_ns = monotonic_ns();
	printf("rig-board-sim: emulated time 0 is CLOCK_MONOTONIC %.9f s\n", board.origin_ns * 1e-9);
	announce_pty(&board);

	avr_cycle_count_t end = (avr_cycle_count_t)(board.options.duration * board.avr->frequency);
	int state = cpu_Running;
	while (!stop_requested && (end == 0 || board.avr->cycle < end)) {
		state = avr_run(board.avr);
		if (state == cpu_Done || state == cpu_Crashed)
			break;
	}
	pty_link_flush(&board.link);
	pty_link_close(&board.link);
	if (board.options.link)
		unlink(board.options.link);
	if (board.led_log)
		fclose(board.led_log);
	printf("rig-board-sim: stopped at %.6f s emulated, %s; stood still %.3f ms while the host was busy\n",
	       cycle_seconds(&board, board.avr->cycle), state == cpu_Crashed ? "firmware crashed" : "ok",
	       board.stalled_ns * 1e-6);
	return state == cpu_Crashed ? 1 : 0;
}
