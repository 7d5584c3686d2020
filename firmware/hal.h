/*
 * Board interface of the ARACHNAE II node firmware. main.c and the behaviours in
 * nodes/ are portable C99 against this header; avr/hal_avr.c implements it for the
 * ATmega328P (the SIL target), m0/hal_m0.c for a Cortex-M0 size image.
 *
 * RS-485 half duplex with /RE tied to DE: the node does not receive while it
 * drives the line. Its echo is checked in hardware instead: a collision-detect
 * latch (TXD XOR the transceiver's RO, sampled at mid-bit) is set when what is
 * on the wire differs from what the node sent; seed 3.2.2 uses the echo to
 * detect a corrupted XMIT_REQ, the sensor bus the same for DATA_RDY. The latch
 * is cleared when the next transmission starts.
 */
#ifndef FW_HAL_H
#define FW_HAL_H
#include <stdint.h>

/* Called by the HAL: a received byte (RX interrupt) and the end of an idle gap of
 * FW_IDLE_GAP_US after the last byte (timer interrupt). Defined in main.c. */
void fw_rx_byte(uint8_t byte);
void fw_rx_gap(void);

void hal_init(void);
void hal_enable_interrupts(void);
/* Sleep until the next interrupt (at the latest the 1 ms tick). */
void hal_idle(void);
/* Milliseconds since reset, wrapping. */
uint16_t hal_ms(void);
/* 1 if no byte was received during the last idle gap (carrier sense before a slave-initiated frame). */
uint8_t hal_line_idle(void);
/* Waits the bus turnaround, drives the line, sends `len` bytes, releases the line. */
void hal_send(const uint8_t *frame, uint16_t len);
/* Echo of the last hal_send(): pending until FW_CD_WAIT_MS after the line was
 * released, then equal (latch clear) or corrupt (latch set). */
enum { HAL_ECHO_PENDING = 0, HAL_ECHO_OK = 1, HAL_ECHO_CORRUPT = 2 };
uint8_t hal_echo_status(void);
/* Digital inputs of the node's sensors (bit 0, bit 1, ...), 1 = active. */
uint8_t hal_inputs(void);
/* Test point / LED, pulsed when the behaviour detects a stimulus. */
void hal_test_point(uint8_t on);

/* Defined by the behaviour (nodes/<role>.c). */
void fw_behaviour_init(void *node);
void fw_behaviour_poll(void *node, uint16_t now_ms);

#endif /* FW_HAL_H */
