/*
 * Issue 15 measurement, not product code: the USRC's per-message code as table-driven field descriptors
 * in flash (PROGMEM) with one generic check / unpack / pack, as nanopb does, to compare with the generated
 * per-message functions (`make -C firmware table-experiment` prints both).
 * A lower bound for the table approach: the engine below handles only what the USRC's messages need
 * (byte-aligned 8- and 16-bit fields with a range); the generated codec also has bit fields, flags masks,
 * node addresses and arrays, which a complete engine would add.
 * Same checks as the generated code: LENGTH, then RANGE per field in order; OPCODE for what the role
 * does not receive.
 */
#include <avr/pgmspace.h>
#include <stdint.h>

#include "arachnae.h"

#define F16 1u   /* 16-bit big-endian field, else 8-bit */
#define FSIGNED 2u

typedef struct {
    uint8_t off;    /* byte offset in the payload */
    uint8_t kind;   /* F16 | FSIGNED */
    uint8_t soff;   /* byte offset in the struct */
    int16_t lo, hi; /* raw range */
} tb_field;

typedef struct {
    uint8_t opcode, len, first, n;   /* fixed length; fields first..first+n-1 */
} tb_msg;

static const tb_field fields[] PROGMEM = {
    {0, F16, 0, 0, 359},              /* HEAD_SET_ABS.angle */
    {0, F16 | FSIGNED, 0, -359, 359}, /* HEAD_SET_REL.angle */
    {0, 0, 0, 0, 255},                /* XMIT_DATA_USRC.distance */
    {1, F16, 1, 0, 359},              /* XMIT_DATA_USRC.angle (struct offset 1 on AVR: no padding) */
    {0, 0, 0, 0, 2},                  /* STATUS_ACK_RANGE.status */
};

/* what the USRC receives (payload check) and sends (check, pack) */
static const tb_msg msgs[] PROGMEM = {
    {ARACHNAE_OP_INIT, 0, 0, 0}, {ARACHNAE_OP_ID_REQ, 0, 0, 0}, {ARACHNAE_OP_STATUS_REQ, 0, 0, 0},
    {ARACHNAE_OP_HEAD_SET_ABS, 2, 0, 1}, {ARACHNAE_OP_HEAD_SET_REL, 2, 1, 1}, {ARACHNAE_OP_HEAD_STEP, 0, 0, 0},
    {ARACHNAE_OP_DO_MEASURE, 0, 0, 0}, {ARACHNAE_OP_FREE_RUN, 0, 0, 0}, {ARACHNAE_OP_XMIT_DATA, 0, 0, 0},
    {ARACHNAE_OP_XMIT_DATA_USRC, 3, 2, 2}, {ARACHNAE_OP_STATUS_ACK_RANGE, 1, 4, 1}, {ARACHNAE_OP_DATA_RDY, 0, 0, 0},
};
#define N_RX 9u   /* the first N_RX entries are what the role receives */

static const tb_msg *find(uint8_t opcode, uint8_t n)
{
    const tb_msg *m = msgs;
    for (; n; n--, m++)
        if (pgm_read_byte(&m->opcode) == opcode)
            return m;
    return 0;
}

static int16_t wire(const uint8_t *p, uint8_t kind)
{
    if (kind & F16)
        return (int16_t)(uint16_t)(((unsigned)p[0] << 8) | p[1]);
    return (int16_t)p[0];
}

static int16_t mem(const uint8_t *p, uint8_t kind)
{
    if (kind & F16)
        return (int16_t)(uint16_t)((unsigned)p[0] | ((unsigned)p[1] << 8));
    return (int16_t)p[0];
}

/* RANGE over the fields of m, each value read by `get` from base */
static arachnae_status range(const tb_msg *m, const uint8_t *base, uint8_t from_wire)
{
    const tb_field *f = &fields[pgm_read_byte(&m->first)];
    uint8_t n = pgm_read_byte(&m->n);
    for (; n; n--, f++) {
        uint8_t kind = pgm_read_byte(&f->kind);
        uint8_t at = pgm_read_byte(from_wire ? &f->off : &f->soff);
        int16_t v = from_wire ? wire(base + at, kind) : mem(base + at, kind);
        if (v < (int16_t)pgm_read_word(&f->lo) || v > (int16_t)pgm_read_word(&f->hi))
            return ARACHNAE_RANGE;
    }
    return ARACHNAE_OK;
}

arachnae_status tb_payload_check(uint8_t opcode, const uint8_t *payload, uint8_t len)
{
    const tb_msg *m = find(opcode, N_RX);
    if (m == 0)
        return ARACHNAE_OPCODE;
    if (len != pgm_read_byte(&m->len))
        return ARACHNAE_LENGTH;
    return range(m, payload, 1);
}

void tb_unpack(uint8_t opcode, const uint8_t *payload, void *out)
{
    const tb_msg *m = find(opcode, N_RX);
    const tb_field *f = &fields[pgm_read_byte(&m->first)];
    uint8_t n = pgm_read_byte(&m->n);
    for (; n; n--, f++) {
        uint8_t kind = pgm_read_byte(&f->kind);
        uint8_t *d = (uint8_t *)out + pgm_read_byte(&f->soff);
        const uint8_t *s = payload + pgm_read_byte(&f->off);
        if (kind & F16) {
            d[0] = s[1];
            d[1] = s[0];
        } else {
            d[0] = s[0];
        }
    }
}

arachnae_status tb_build(uint8_t opcode, const void *msg, uint8_t dst, uint8_t src, uint8_t *frame, uint16_t cap,
                         uint16_t *frame_len)
{
    const tb_msg *m = find(opcode, sizeof msgs / sizeof msgs[0]);
    const tb_field *f = &fields[pgm_read_byte(&m->first)];
    uint8_t n = pgm_read_byte(&m->n), len = pgm_read_byte(&m->len);
    arachnae_status st = range(m, (const uint8_t *)msg, 0);
    if (st != ARACHNAE_OK)
        return st;
    if (cap < (uint16_t)(ARACHNAE_FRAME_OVERHEAD + len))
        return ARACHNAE_BUFFER;
    for (; n; n--, f++) {
        uint8_t kind = pgm_read_byte(&f->kind);
        const uint8_t *s = (const uint8_t *)msg + pgm_read_byte(&f->soff);
        uint8_t *d = frame + ARACHNAE_FRAME_PAYLOAD + pgm_read_byte(&f->off);
        if (kind & F16) {
            d[0] = s[1];
            d[1] = s[0];
        } else {
            d[0] = s[0];
        }
    }
    frame[ARACHNAE_FRAME_OPCODE] = opcode;
    frame[ARACHNAE_FRAME_LENGTH] = len;
    return arachnae_frame_seal(frame, dst, src, frame_len);
}

/* the typed API the behaviours call stays: thin wrappers */
arachnae_status tb_xmit_data_usrc_build(const arachnae_xmit_data_usrc_t *m, uint8_t dst, uint8_t src, uint8_t *frame,
                                        uint16_t cap, uint16_t *frame_len)
{
    return tb_build(ARACHNAE_OP_XMIT_DATA_USRC, m, dst, src, frame, cap, frame_len);
}

arachnae_status tb_data_rdy_build(uint8_t dst, uint8_t src, uint8_t *frame, uint16_t cap, uint16_t *frame_len)
{
    return tb_build(ARACHNAE_OP_DATA_RDY, 0, dst, src, frame, cap, frame_len);
}
