/*
 * hal.h for the ATmega328P at 16 MHz (the SIL target, firmware/sil/).
 * USART0 8N1 at the role's bus baud; PD2 drives the RS-485 DE and /RE together,
 * the receiver is off while sending; PC2 reads the collision-detect latch (hal.h).
 * Timer0: 1 ms tick. Timer1: one-shot idle-gap timer, restarted by every byte.
 * Inputs on PC0..PC1 (active low, pull-ups); test point on PB5. PC3: carrier detect, the
 * transceiver's RO through a retriggerable monostable of one character: high from a frame's
 * start bit on, before its first byte is in (hal_line_quiet_ms).
 */
#include <avr/interrupt.h>
#include <avr/io.h>
#include <avr/sleep.h>
#include <util/atomic.h>

#include "role_config.h"
#include "hal.h"

#ifndef F_CPU
#error "F_CPU must be defined (16000000UL)"
#endif
#define BAUD FW_BAUD
#include <util/setbaud.h>
#include <util/delay.h>

#define T1_PRESCALE 64UL
#define GAP_TICKS ((F_CPU / T1_PRESCALE) * FW_IDLE_GAP_US / 1000000UL)
#if GAP_TICKS > 65535UL || GAP_TICKS < 2UL
#error "idle gap does not fit Timer1 with prescaler 64"
#endif
#define T1_START ((uint8_t)(_BV(WGM12) | _BV(CS11) | _BV(CS10))) /* CTC, clk/64 */

static volatile uint16_t ms;
static volatile uint16_t last_rx_ms;
static volatile uint16_t tx_end_ms;
volatile uint8_t fw_rx_from_master = 1;   /* hal.h; nothing heard yet counts as the master's */
static uint8_t sent;   /* 1 once hal_send() ran: there is an echo to judge */

void hal_init(void)
{
    DDRD |= _BV(PD2);                 /* DE, low: listening */
    PORTD &= (uint8_t)~_BV(PD2);
    DDRB |= _BV(PB5);                 /* test point */
    DDRC &= (uint8_t)~(_BV(PC0) | _BV(PC1) | _BV(PC2) | _BV(PC3));
    PORTC |= _BV(PC0) | _BV(PC1);     /* pull-ups: a closed switch reads 0 */

    UBRR0H = UBRRH_VALUE;
    UBRR0L = UBRRL_VALUE;
#if USE_2X
    UCSR0A |= _BV(U2X0);
#else
    UCSR0A &= (uint8_t)~_BV(U2X0);
#endif
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);               /* 8N1 */
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);

    TCCR0A = _BV(WGM01);                               /* CTC, 1 kHz */
    OCR0A = (uint8_t)(F_CPU / 64UL / 1000UL - 1UL);
    TCCR0B = _BV(CS01) | _BV(CS00);
    TIMSK0 = _BV(OCIE0A);

    TCCR1A = 0;
    OCR1A = (uint16_t)GAP_TICKS;
    TIMSK1 = _BV(OCIE1A);
}

void hal_enable_interrupts(void) { sei(); }

void hal_idle(void)
{
    /* idle mode (SM2..0 = 0): the UART and the timers keep running; avr-libc's
       set_sleep_mode() macro trips -Wconversion, so the register is written here */
    SMCR = _BV(SE);
    sleep_cpu();
    SMCR = 0;
}

uint16_t hal_ms(void)
{
    uint16_t v;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { v = ms; }
    return v;
}

uint8_t hal_line_idle(void)
{
    uint8_t running = (uint8_t)(TCCR1B != 0u);  /* the gap timer runs from a byte until the gap */
    return (uint8_t)(!running);
}

ISR(TIMER0_COMPA_vect)
{
    ms++;
}

ISR(TIMER1_COMPA_vect)
{
    TCCR1B = 0;                                 /* one-shot */
    fw_rx_gap();
}

ISR(USART_RX_vect)
{
    uint8_t byte = UDR0;
    last_rx_ms = ms;
    TCNT1 = 0;
    TCCR1B = T1_START;
    fw_rx_byte(byte);
}

void hal_send(const uint8_t *frame, uint16_t len)
{
    uint16_t i;
    _delay_us(FW_TURNAROUND_US);                /* let the previous sender release the line */
    UCSR0B &= (uint8_t)~_BV(RXEN0);             /* /RE follows DE */
    PORTD |= _BV(PD2);                          /* also clears the collision latch */
    UCSR0A |= _BV(TXC0);                        /* clear a stale transmit-complete flag */
    for (i = 0; i < len; i++) {
        while (!(UCSR0A & _BV(UDRE0)))
            ;
        UDR0 = frame[i];
    }
    while (!(UCSR0A & _BV(TXC0)))
        ;
    PORTD &= (uint8_t)~_BV(PD2);
    UCSR0B |= _BV(RXEN0);
    fw_rx_from_master = 0;                      /* the line's last frame is ours (hal.h) */
    tx_end_ms = hal_ms();
    sent = 1;
}

uint8_t hal_echo_status(void)
{
    if (!sent || (uint16_t)(hal_ms() - tx_end_ms) < FW_CD_WAIT_MS)
        return HAL_ECHO_PENDING;
    return (PINC & _BV(PC2)) ? HAL_ECHO_CORRUPT : HAL_ECHO_OK;
}

uint16_t hal_line_quiet_ms(void)
{
    uint16_t now = hal_ms(), rx;
    ATOMIC_BLOCK(ATOMIC_RESTORESTATE) { rx = last_rx_ms; }
    if (TCCR1B != 0u || (PINC & _BV(PC3)))       /* a frame is coming in, or just began */
        return 0;
    rx = (uint16_t)(now - rx);
    return sent && (uint16_t)(now - tx_end_ms) < rx ? (uint16_t)(now - tx_end_ms) : rx;
}

/* Sensor front end on GPIOR0..2 (firmware/sil/sil_host.c answers in the SIL): argument in
   GPIOR1/GPIOR2, the request code in GPIOR0, then the reply bytes read from GPIOR0. */
static void port_request(uint8_t code, uint16_t arg)
{
    GPIOR1 = (uint8_t)arg;
    GPIOR2 = (uint8_t)(arg >> 8);
    GPIOR0 = code;
}

void hal_sample(uint8_t kind, uint16_t arg, int16_t *out, uint8_t n)
{
    uint8_t i;
    port_request(kind, arg);
    for (i = 0; i < n; i++) {
        uint8_t lo = GPIOR0;
        out[i] = (int16_t)((uint16_t)lo | (uint16_t)((uint16_t)GPIOR0 << 8));
    }
}

void hal_note(uint8_t kind, uint16_t arg) { port_request(kind, arg); }

uint8_t hal_inputs(void) { return (uint8_t)((uint8_t)~PINC & 0x03u); }

void hal_test_point(uint8_t on)
{
    if (on)
        PORTB |= _BV(PB5);
    else
        PORTB &= (uint8_t)~_BV(PB5);
}
