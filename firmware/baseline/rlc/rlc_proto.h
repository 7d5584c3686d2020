/* Hand-written RLC protocol code (baseline): dispatch and the behaviour's hooks. */
#ifndef RLC_PROTO_H
#define RLC_PROTO_H
#include <stdint.h>

void bl_dispatch(const uint8_t *f);

/* behaviour */
void bl_on_init(void);
uint8_t bl_on_status(void);
void bl_on_xmit_grant(void);
#endif
