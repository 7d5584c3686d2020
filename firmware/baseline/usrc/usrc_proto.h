/* Hand-written USRC protocol code (baseline): dispatch and the behaviour's hooks. */
#ifndef USRC_PROTO_H
#define USRC_PROTO_H
#include <stdint.h>

void bl_dispatch(const uint8_t *f);
void bl_data_rdy(uint8_t master);

/* behaviour */
void bl_on_init(void);
uint8_t bl_on_status(void);
void bl_on_head_abs(uint16_t angle);
void bl_on_head_rel(int16_t angle);
void bl_on_head_step(void);
void bl_on_do_measure(void);
uint16_t bl_on_xmit_data(uint8_t *distance);   /* returns the angle */
#endif
