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
/* Counters of main.c a debugger or a behaviour can read: frames for us, frames refused (any
 * reason, also frames for other nodes), overruns, checked requests the skeleton could not answer,
 * and corrupt frames heard (collisions). */
extern volatile uint16_t fw_rx_frames, fw_rx_errors, fw_rx_overruns, fw_rx_unanswered, fw_rx_corrupt;
/* What the line carried (main.c, every frame heard, whoever it was for): hal_ms() when the last corrupt
 * frame ended, and characters of intact frames other than the bus's request message (the backoff window's
 * slots are idle slots, behaviours/runtime.py). */
extern volatile uint16_t fw_rx_corrupt_ms, fw_rx_pause_chars;
/* 1 if the last frame on the line came from the bus master or was corrupt (a polled reply may be due,
 * runtime._slave_start): set by main.c for every frame heard, cleared by hal_send() (our own frame). */
extern volatile uint8_t fw_rx_from_master;

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

/* Milliseconds since a byte was last on the line: received, or the end of our own frame
 * (carrier sense before a slave-initiated frame, seed 3.2.2 "when the bus is idle"). */
uint16_t hal_line_quiet_ms(void);

/* The board's sensor front end (ADC, sonar timer, probe bus): one conversion of the
 * kind below, `n` values in the reply field's raw steps (the transfer function of the
 * front end is the spec's encoding of the XMIT_DATA_<role> field, behaviours.units),
 * written to out[]. SAMPLE_SONAR: arg = head angle; out[0] = distance, out[1] = echo
 * time in microseconds. */
enum { HAL_SAMPLE_SONAR = 1, HAL_SAMPLE_IR = 2, HAL_SAMPLE_INCLINATION = 3, HAL_SAMPLE_TEMPERATURES = 4,
       HAL_SAMPLE_LIGHT = 5, HAL_SAMPLE_BATTERY = 6 };
void hal_sample(uint8_t kind, uint16_t arg, int16_t *out, uint8_t n);
/* A debug-port event (what a Python node writes with hw.note): kind, one argument.
 * NOTE_REFLEX: the reflex source raised a reflex request (tracecheck's reflex_rate rule). */
enum { HAL_NOTE_STIMULUS = 0x40, HAL_NOTE_ALARM = 0x41, HAL_NOTE_STATUS = 0x42, HAL_NOTE_REFLEX = 0x43 };
enum { HAL_STIMULUS_WHISKER = 0, HAL_STIMULUS_IR = 1 };
void hal_note(uint8_t kind, uint16_t arg);

/* The debug record a debugger (or the SIL bridge) reads from RAM at the end of a run:
 * the figures a Python sensor reports with debug_metrics(). Each behaviour fills the
 * entries it has; firmware/sil_bridge.py reads the names from this enum. */
enum fw_debug_index {
    FW_DBG_ALARMS, FW_DBG_STATUS, FW_DBG_MEASUREMENTS, FW_DBG_SECOND_SETS,
    FW_DBG_MEAN, FW_DBG_MEAN_MIN, FW_DBG_LEVEL_MIN, FW_DBG_COUNT
};
extern volatile int16_t fw_debug[FW_DBG_COUNT];

/* Defined by the behaviour (nodes/<role>.c). */
void fw_behaviour_init(void *node);
void fw_behaviour_poll(void *node, uint16_t now_ms);

#endif /* FW_HAL_H */
