/*
 * RLC protocol code as a firmware engineer writes it by hand (baseline, a first-level bus
 * node): a switch over opcodes; every request it takes has an empty payload.
 */
#include <stdint.h>

#include "bl_frame.h"
#include "bl_role.h"
#include "rlc_proto.h"

void bl_dispatch(const uint8_t *f)
{
    uint8_t v;
    if (f[3] != 0u)
        return;
    switch (f[2]) {
    case BL_OP_INIT:
        bl_on_init();
        break;
    case BL_OP_ID_REQ:
        bl_reply(f, BL_OP_ID_ACK, BL_OWN);
        break;
    case BL_OP_STATUS_REQ:
        v = bl_on_status();
        if (v <= 1u)
            bl_reply(f, BL_OP_STATUS_ACK_BUSY, v);
        break;
    case BL_OP_XMIT_GRANT:
        bl_on_xmit_grant();
        break;
    default:
        break;
    }
}
