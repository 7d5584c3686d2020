/* Behaviour hooks of the USRC baseline: only what makes every protocol path reachable (the size
 * comparison is of the protocol code, usrc_proto.c and bl_frame.c). */
#include "hal.h"
#include "usrc_proto.h"

static uint16_t angle;
static uint8_t measure, status;

void bl_on_init(void) { status = 0; }
uint8_t bl_on_status(void) { return status; }
void bl_on_head_abs(uint16_t a) { angle = a; }
void bl_on_head_rel(int16_t d) { angle = (uint16_t)((int16_t)angle + d); }
void bl_on_head_step(void) { angle++; }
void bl_on_do_measure(void) { measure = 1; }

uint16_t bl_on_xmit_data(uint8_t *distance)
{
    *distance = hal_inputs();
    return angle;
}

void bl_poll(uint16_t now);
void bl_poll(uint16_t now)
{
    (void)now;
    if (measure && hal_line_idle()) {
        measure = 0;
        bl_data_rdy(0x04u);        /* SPU */
    }
}
