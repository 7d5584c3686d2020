/*
 * Frame layer of the hand-written baselines (USRC, RLC): one receive buffer of the largest
 * frame the role takes, the length byte checked against it as soon as it is in, a bitwise
 * CRC-16/IBM-3740, the own-or-broadcast address check; one send routine.
 */
#include <string.h>

#include "hal.h"
#include "bl_frame.h"
#include "bl_role.h"

uint8_t bl_rx_buf[BL_RX_MAX];
static uint8_t rx_n, rx_skip;

uint16_t bl_crc16(const uint8_t *p, uint8_t n)
{
    uint16_t crc = 0xFFFFu;
    uint8_t i;
    while (n--) {
        crc = (uint16_t)(crc ^ (uint16_t)((uint16_t)*p++ << 8));
        for (i = 0; i < 8u; i++)
            crc = (crc & 0x8000u) ? (uint16_t)((uint16_t)(crc << 1) ^ 0x1021u) : (uint16_t)(crc << 1);
    }
    return crc;
}

uint8_t bl_rx_byte(uint8_t byte)
{
    uint8_t need;
    if (rx_skip)
        return 0;
    bl_rx_buf[rx_n++] = byte;
    if (rx_n < 4u)
        return 0;
    need = (uint8_t)(bl_rx_buf[3] + 6u);
    if (bl_rx_buf[3] > BL_RX_MAX - 6u) {   /* longer than anything this role receives */
        rx_skip = 1;
        return 0;
    }
    if (rx_n < need)
        return 0;
    rx_skip = 1;                           /* the frame is complete: nothing more until the gap */
    if (bl_crc16(bl_rx_buf, (uint8_t)(need - 2u)) !=
        (uint16_t)(((uint16_t)bl_rx_buf[need - 2u] << 8) | bl_rx_buf[need - 1u]))
        return 0;
    return (uint8_t)(bl_rx_buf[0] == BL_OWN || bl_rx_buf[0] == BL_BROADCAST);
}

void bl_rx_gap(void)
{
    rx_n = 0;
    rx_skip = 0;
}

void bl_send(uint8_t dst, uint8_t opcode, const uint8_t *payload, uint8_t n)
{
    uint8_t f[BL_TX_MAX];
    uint16_t crc;
    f[0] = dst;
    f[1] = BL_OWN;
    f[2] = opcode;
    f[3] = n;
    memcpy(&f[4], payload, n);
    crc = bl_crc16(f, (uint8_t)(4u + n));
    f[4 + n] = (uint8_t)(crc >> 8);
    f[5 + n] = (uint8_t)crc;
    hal_send(f, (uint16_t)(6u + n));
}

void bl_reply(const uint8_t *f, uint8_t opcode, uint8_t v)
{
    if (f[0] == BL_OWN)
        bl_send(f[1], opcode, &v, 1);
}
