/* Hand-written frame layer shared by the baselines (the TPSC's CRC and send, all of it for USRC and RLC):
 * what a firmware engineer writes once, sized by the role's BL_OWN, BL_RX_MAX, BL_TX_MAX (baseline/<role>/bl_role.h). */
#ifndef BL_FRAME_H
#define BL_FRAME_H
#include <stdint.h>

#define BL_BROADCAST 0xFFu

uint16_t bl_crc16(const uint8_t *p, uint8_t n);
/* Receiver (RX interrupt): 1 when a whole frame with a good CRC for BL_OWN or broadcast is in bl_rx_buf. */
uint8_t bl_rx_byte(uint8_t byte);
void bl_rx_gap(void);
extern uint8_t bl_rx_buf[];
/* Builds and sends one frame from BL_OWN (payload of n <= BL_TX_MAX - 6 bytes). */
void bl_send(uint8_t dst, uint8_t opcode, const uint8_t *payload, uint8_t n);
/* A one-byte reply to the sender of request f, unless f went to broadcast. */
void bl_reply(const uint8_t *f, uint8_t opcode, uint8_t v);
#endif
