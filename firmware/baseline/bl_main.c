/*
 * Main loop of the hand-written baselines built on bl_frame.c (USRC, RLC): the RX interrupt
 * feeds the receiver, the main loop dispatches a complete frame (the TPSC's is tpsc_baseline.c).
 */
#include "hal.h"
#include "bl_frame.h"
#include "bl_role.h"

void bl_dispatch(const uint8_t *f);
/* the behaviour's loop (<role>_baseline.c) */
void bl_poll(uint16_t now);

static volatile uint8_t ready;

void fw_rx_byte(uint8_t byte)
{
    if (!ready && bl_rx_byte(byte))
        ready = 1;
}

void fw_rx_gap(void) { bl_rx_gap(); }

/* the dispatch entry, named for the stack analysis */
void fw_dispatch(void);
void fw_dispatch(void)
{
    bl_dispatch(bl_rx_buf);
}

int main(void)
{
    hal_init();
    hal_enable_interrupts();
    for (;;) {
        if (ready) {
            fw_dispatch();
            ready = 0;
        }
        bl_poll(hal_ms());
        hal_idle();
    }
}
