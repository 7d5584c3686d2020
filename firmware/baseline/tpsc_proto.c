/*
 * TPSC protocol code as a firmware engineer writes it by hand: one receive buffer
 * of the largest frame the TPSC takes (6 bytes, it receives only empty payloads),
 * a switch over opcodes, memcpy of the fields, a bitwise CRC-16/IBM-3740 (bl_frame.c, with the send).
 * Same wire behaviour as the generated skeleton for the frames a TPSC accepts;
 * it checks less (no per-message LENGTH/RANGE table, one fixed buffer).
 */
#include "hal.h"
#include "tpsc_proto.h"

uint8_t bl_frame[6];
static uint8_t rx_n, rx_skip;

uint8_t bl_rx(uint8_t byte)
{
    if (rx_skip)
        return 0;
    if (rx_n >= sizeof bl_frame) {      /* longer than anything a TPSC receives */
        rx_skip = 1;
        return 0;
    }
    bl_frame[rx_n++] = byte;
    if (rx_n == 4u && bl_frame[3] != 0u) {   /* every request to a TPSC has an empty payload */
        rx_skip = 1;
        return 0;
    }
    if (rx_n < sizeof bl_frame)
        return 0;
    if (bl_crc16(bl_frame, 4) != (uint16_t)(((uint16_t)bl_frame[4] << 8) | bl_frame[5]))
        return 0;
    return (uint8_t)(bl_frame[0] == BL_OWN || bl_frame[0] == BL_BROADCAST);
}

void bl_gap(void)
{
    rx_n = 0;
    rx_skip = 0;
}

void bl_dispatch(const uint8_t *f)
{
    uint8_t v;
    uint8_t to_us = (uint8_t)(f[0] == BL_OWN);
    switch (f[2]) {
    case BL_OP_INIT:
        bl_on_init();
        break;
    case BL_OP_ID_REQ:
        v = BL_OWN;
        if (to_us)
            bl_send(f[1], BL_OP_ID_ACK, &v, 1);
        break;
    case BL_OP_STATUS_REQ:
        v = 0;                          /* seed 3.2.12: always IN_ORDER */
        if (to_us)
            bl_send(f[1], BL_OP_STATUS_ACK_ORDER, &v, 1);
        break;
    case BL_OP_XMIT_DATA:
        if (to_us) {
            v = bl_on_xmit_data();
            bl_send(f[1], BL_OP_XMIT_DATA_TPSC, &v, 1);
        }
        break;
    default:
        break;
    }
}
