/*
 * Echo firmware for testing the SIL host: every byte received on USART0 at the
 * sensor bus's baud rate is sent back plus one, with PD2 (RS-485 DE) high while
 * sending. The rate is the spec's (seed 3.2.1): the TPSC's build configuration
 * (firmware/roles.py config), so no bus constant is typed in here.
 */
#include <avr/interrupt.h>
#include <avr/io.h>

#include "role_config.h"
#define BAUD FW_BAUD
#include <util/setbaud.h>

ISR(USART_RX_vect)
{
    uint8_t b = UDR0;
    PORTD |= _BV(PD2);
    while (!(UCSR0A & _BV(UDRE0)))
        ;
    UDR0 = (uint8_t)(b + 1u);
    while (!(UCSR0A & _BV(TXC0)))
        ;
    UCSR0A |= _BV(TXC0);
    PORTD &= (uint8_t)~_BV(PD2);
}

int main(void)
{
    DDRD |= _BV(PD2);
    UBRR0H = UBRRH_VALUE;
    UBRR0L = UBRRL_VALUE;
    UCSR0C = _BV(UCSZ01) | _BV(UCSZ00);
    UCSR0B = _BV(RXEN0) | _BV(TXEN0) | _BV(RXCIE0);
    sei();
    for (;;)
        ;
}
