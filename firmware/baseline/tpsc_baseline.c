/*
 * Hand-written TPSC firmware (baseline): main loop and the same whisker behaviour
 * as nodes/tpsc.c, on the same HAL, without any generated code.
 */
#include "hal.h"
#include "role_config.h"
#include "tpsc_proto.h"

#define SCAN_MS 20u

static volatile uint8_t ready;
static uint8_t contact, latched, data_rdy, waiting_echo;
static uint16_t last_scan, backoff_until;

void fw_rx_byte(uint8_t byte)
{
    if (!ready && bl_rx(byte))
        ready = 1;
}

void fw_rx_gap(void) { bl_gap(); }

void bl_on_init(void)
{
    latched = 0;
    data_rdy = 0;
    waiting_echo = 0;
}

uint8_t bl_on_xmit_data(void)
{
    uint8_t v = latched ? latched : contact;
    latched = 0;
    return v;
}

static uint8_t code(uint8_t in)
{
    if ((in & 3u) == 3u)
        return 0x40u;
    if (in & 1u)
        return 0x10u;
    return (in & 2u) ? 0x20u : 0u;
}

void fw_behaviour_init(void *node) { (void)node; }

void fw_behaviour_poll(void *node, uint16_t now)
{
    (void)node;
    if ((uint16_t)(now - last_scan) >= SCAN_MS) {
        uint8_t c = code(hal_inputs());
        last_scan = now;
        if (c && c != contact) {
            latched = c;
            data_rdy = 1;
        }
        contact = c;
    }
    if (waiting_echo) {
        uint8_t e = hal_echo_status();
        if (e == HAL_ECHO_OK) {
            waiting_echo = 0;
            data_rdy = 0;
        } else if (e == HAL_ECHO_CORRUPT) {
            waiting_echo = 0;
            backoff_until = (uint16_t)(now + (FW_BACKOFF_RANK + 1u) * FW_BACKOFF_SLOT_US / 1000u);
        }
    } else if (data_rdy && (int16_t)(now - backoff_until) >= 0 && hal_line_idle()) {
        bl_send(BL_SPU, BL_OP_DATA_RDY, 0, 0);
        waiting_echo = 1;
    }
}

/* the dispatch entry, named for the stack analysis */
void fw_dispatch(void);
void fw_dispatch(void)
{
    bl_dispatch(bl_frame);
}

int main(void)
{
    hal_init();
    fw_behaviour_init(0);
    hal_enable_interrupts();
    for (;;) {
        if (ready) {
            fw_dispatch();
            ready = 0;
        }
        fw_behaviour_poll(0, hal_ms());
        hal_idle();
    }
}
