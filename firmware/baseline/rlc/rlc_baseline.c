/* Behaviour hooks of the RLC baseline: only what makes every protocol path reachable (the size
 * comparison is of the protocol code, rlc_proto.c and bl_frame.c). */
#include "hal.h"
#include "rlc_proto.h"

static uint8_t granted, status;

void bl_on_init(void) { status = 0; }
uint8_t bl_on_status(void) { return status; }
void bl_on_xmit_grant(void) { granted = 1; }

void bl_poll(uint16_t now);
void bl_poll(uint16_t now)
{
    (void)now;
    if (granted) {
        granted = 0;
        hal_test_point(1);
    }
}
