/*
 * USRC protocol code as a firmware engineer writes it by hand (baseline): a switch over
 * opcodes with each payload's length and range checked inline, replies built on the stack.
 * Same wire behaviour as the generated skeleton for the frames a USRC accepts.
 */
#include <stdint.h>

#include "bl_frame.h"
#include "bl_role.h"
#include "usrc_proto.h"

void bl_dispatch(const uint8_t *f)
{
    uint8_t v[3], n = f[3];
    uint16_t a = (uint16_t)(((uint16_t)f[4] << 8) | f[5]);
    switch (f[2]) {
    case BL_OP_INIT:
        if (n == 0u)
            bl_on_init();
        break;
    case BL_OP_ID_REQ:
        if (n == 0u)
            bl_reply(f, BL_OP_ID_ACK, BL_OWN);
        break;
    case BL_OP_STATUS_REQ:
        v[0] = bl_on_status();
        if (n == 0u && v[0] <= 2u)
            bl_reply(f, BL_OP_STATUS_ACK_RANGE, v[0]);
        break;
    case BL_OP_HEAD_SET_ABS:
        if (n == 2u && a <= 359u)
            bl_on_head_abs(a);
        break;
    case BL_OP_HEAD_SET_REL:
        if (n == 2u && (a <= 359u || a >= (uint16_t)(0x10000UL - 359u)))
            bl_on_head_rel((int16_t)(a <= 359u ? (int16_t)a : (int16_t)-(int16_t)(uint16_t)(0x10000UL - a)));
        break;
    case BL_OP_HEAD_STEP:
        if (n == 0u)
            bl_on_head_step();
        break;
    case BL_OP_DO_MEASURE:
        if (n == 0u)
            bl_on_do_measure();
        break;
    case BL_OP_XMIT_DATA:
        if (n == 0u && f[0] == BL_OWN) {
            a = bl_on_xmit_data(&v[0]);
            v[1] = (uint8_t)(a >> 8);
            v[2] = (uint8_t)a;
            if (a <= 359u)
                bl_send(f[1], BL_OP_XMIT_DATA_USRC, v, 3);
        }
        break;
    default:
        break;
    }
}

void bl_data_rdy(uint8_t master)
{
    bl_send(master, BL_OP_DATA_RDY, 0, 0);
}
