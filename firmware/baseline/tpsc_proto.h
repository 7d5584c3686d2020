/* Hand-written TPSC protocol code, the baseline the generated codec is compared with. */
#ifndef TPSC_PROTO_H
#define TPSC_PROTO_H
#include <stdint.h>

#define BL_OWN 0x28u
#define BL_SPU 0x04u
#define BL_BROADCAST 0xFFu
#define BL_OP_INIT 0x01u
#define BL_OP_ID_REQ 0x02u
#define BL_OP_ID_ACK 0x03u
#define BL_OP_STATUS_REQ 0x04u
#define BL_OP_STATUS_ACK_ORDER 0x06u
#define BL_OP_XMIT_DATA 0x45u
#define BL_OP_DATA_RDY 0x46u
#define BL_OP_XMIT_DATA_TPSC 0x48u

/* 1 when a valid frame for us is in bl_frame (ISR side). */
uint8_t bl_rx(uint8_t byte);
void bl_gap(void);
extern uint8_t bl_frame[6];
/* Handles the frame in f; calls the behaviour for INIT and XMIT_DATA. */
void bl_dispatch(const uint8_t *f);
void bl_send(uint8_t dst, uint8_t opcode, const uint8_t *payload, uint8_t n);

/* behaviour */
void bl_on_init(void);
uint8_t bl_on_xmit_data(void);   /* returns the contact byte to send */
#endif
