/* Hand-written TPSC protocol code, the baseline the generated codec is compared with. */
#ifndef TPSC_PROTO_H
#define TPSC_PROTO_H
#include <stdint.h>

#include "bl_frame.h"
#include "bl_role.h"

/* 1 when a valid frame for us is in bl_frame (ISR side). */
uint8_t bl_rx(uint8_t byte);
void bl_gap(void);
extern uint8_t bl_frame[6];
/* Handles the frame in f; calls the behaviour for INIT and XMIT_DATA. */
void bl_dispatch(const uint8_t *f);

/* behaviour */
void bl_on_init(void);
uint8_t bl_on_xmit_data(void);   /* returns the contact byte to send */
#endif
