/*
 * The board's wiring and clocks (ATmega328P at 16 MHz: Arduino Uno or Nano), shared by the
 * firmware and the emulated board in ../sim so that both use the same pins.
 *
 *   encoder A   PD2 / INT0   (Arduino D2)
 *   encoder B   PD3 / INT1   (Arduino D3)
 *   LED         PD6 / OC0A   (Arduino D6, PWM)
 *   photodiode  PC0 / ADC0   (Arduino A0)
 *   host link   PD0 / PD1    (USART0, through the board's USB-serial bridge)
 */
#ifndef RIG_BOARD_H
#define RIG_BOARD_H

#define BOARD_CPU_HZ 16000000UL
#define BOARD_MCU "atmega328p"

#define BOARD_ENCODER_PORT 'D'
#define BOARD_ENCODER_A_BIT 2
#define BOARD_ENCODER_B_BIT 3
#define BOARD_LED_PORT 'D'
#define BOARD_LED_BIT 6
#define BOARD_PHOTODIODE_CHANNEL 0

/* Timer 1 counts CPU clocks / 8: the RIG_TICK_HZ board clock. */
#define BOARD_TIMER1_PRESCALE 8
/* The ADC clock is the CPU clock / 128 (125 kHz); free-running, one sample per 13 ADC clocks. */
#define BOARD_ADC_PRESCALE 128
/* The ADC samples its input 1.5 ADC clocks after a conversion starts, which in free-running
 * mode is 11.5 ADC clocks before that conversion completes and raises its interrupt. */
#define BOARD_ADC_SAMPLE_LEAD_HALF_CLOCKS 23

#endif
