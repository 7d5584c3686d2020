/*
 * libFuzzer target: the generated C frame parser and decoders on hostile input
 * (clang -fsanitize=fuzzer,address,undefined; see firmware/Makefile `fuzz`).
 *
 * Input: byte 0 is the receiving node's own address, the rest is what arrives on
 * the line between two idle gaps. Besides the sanitizers (no read or write past
 * a buffer, no undefined behaviour) every input is held to these oracles:
 *   1. the byte parser (feed every byte, then the gap) gives the same verdict as
 *      the whole-frame check arachnae_frame_decode;
 *   2. a frame that decodes re-encodes to exactly the same bytes (one encoding per
 *      value: nothing is accepted that the encoder would not produce);
 *   3. the receiving role's skeleton (dispatch and its parser with the role's
 *      payload check) agrees with the whole-frame verdict, OPCODE for a message the
 *      role does not receive;
 *   3b. the role's own parser (node_<role>.c, built with the role's buffer size, address and check) gives
 *      the verdict, and passes the frame, that the generic parser gives with the same buffer size, own
 *      address and check (the two are one template, codegen/templates/c/parser.j2);
 *   4. a decoder given a payload of the claimed length reads nothing beyond it
 *      (the payload is copied to a heap block of exactly that size).
 * Every input is checked twice: as it is, and with its last two bytes replaced by
 * the CRC of the bytes before them, so the mutations reach the decoders behind
 * the checksum instead of dying at it.
 * A failed oracle aborts, so libFuzzer keeps the input as a crash.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "arachnae_generic.h"
#include "fuzz_roles.h"

#define FZ_ROLES (sizeof fz_roles / sizeof fz_roles[0])

static void fail(const char *what, int a, int b)
{
    fprintf(stderr, "fuzz_frame: %s (%d vs %d)\n", what, a, b);
    abort();
}

/* Verdict of the byte parser for one burst: the last status feed() reported (an
 * OVERSIZE supersedes an earlier OK), else what the gap reports. With `passed`: the frame the
 * parser holds after an OK verdict (in buf, ARACHNAE_MAX_FRAME bytes), else NULL. */
static arachnae_status parse_burst(const uint8_t *data, uint16_t len, uint16_t own, arachnae_payload_check_fn check,
                                   uint8_t *buf, uint16_t cap, const uint8_t **passed)
{
    arachnae_parser p;
    arachnae_status verdict = ARACHNAE_NONE, st;
    uint16_t i, flen = 0;
    arachnae_parser_init(&p, buf, cap, own, check);
    for (i = 0; i < len; i++) {
        st = arachnae_parser_feed(&p, data[i]);
        if (st != ARACHNAE_NONE)
            verdict = st;
        if (st == ARACHNAE_OK && (arachnae_parser_frame(&p, &flen) == 0 || flen != i + 1u))
            fail("parser_frame disagrees with feed", (int)flen, (int)i + 1);
    }
    st = arachnae_parser_gap(&p);
    if (verdict == ARACHNAE_NONE)
        verdict = st;
    if (passed != NULL)
        *passed = (verdict == ARACHNAE_OK) ? arachnae_parser_frame(&p, &flen) : NULL;
    /* after the gap the parser is ready again: a valid frame goes through */
    return verdict;
}

static void check_frame(uint8_t own, const uint8_t *frame, uint16_t len)
{
    arachnae_header h;
    arachnae_message m;
    arachnae_status whole, parsed;
    uint8_t pbuf[ARACHNAE_MAX_FRAME];
    size_t r;

    /* 1. whole frame vs byte parser, generic payload check */
    memset(&m, 0xA5, sizeof m);
    whole = arachnae_frame_decode(frame, len, own, &h, &m);
    if (len > 0u) {
        parsed = parse_burst(frame, len, own, arachnae_payload_check, pbuf, ARACHNAE_MAX_FRAME, NULL);
        if (parsed != whole)
            fail("byte parser and whole-frame check disagree", (int)parsed, (int)whole);
    }

    /* 2. canonical encoding */
    if (whole == ARACHNAE_OK) {
        uint8_t out[ARACHNAE_MAX_FRAME];
        uint16_t n = 0;
        arachnae_status st = arachnae_frame_build(&m, h.dst, h.src, out, sizeof out, &n);
        if (st != ARACHNAE_OK)
            fail("a decoded message does not encode", (int)st, 0);
        if (n != len || memcmp(out, frame, len) != 0)
            fail("re-encoding differs from the frame", (int)n, (int)len);
    }

    /* 3. the skeleton of the role that owns `own`: its parser agrees with the whole-frame verdict, and
     * dispatch takes every frame that parser passes */
    for (r = 0; r < FZ_ROLES; r++) {
        arachnae_status disp, expect, role_parsed;
        const uint8_t *passed = NULL;
        if (fz_roles[r].dispatch(own, NULL) == ARACHNAE_NONE)
            continue;   /* own is not an address of this role */
        expect = whole;
        if ((whole == ARACHNAE_OK || whole >= ARACHNAE_OPCODE) && len >= ARACHNAE_FRAME_OVERHEAD
            && fz_roles[r].check(frame[ARACHNAE_FRAME_OPCODE], frame + ARACHNAE_FRAME_PAYLOAD,
                                 frame[ARACHNAE_FRAME_LENGTH]) == ARACHNAE_OPCODE)
            expect = ARACHNAE_OPCODE;
        if (len == 0u)
            continue;
        role_parsed = parse_burst(frame, len, own, fz_roles[r].check, pbuf, ARACHNAE_MAX_FRAME, &passed);
        if (role_parsed != expect)
            fail(fz_roles[r].name, (int)role_parsed, (int)expect);
        {
            /* 3b. the role's own parser against the generic one with the role's buffer size */
            uint8_t gbuf[ARACHNAE_MAX_FRAME], rbuf[ARACHNAE_MAX_FRAME];
            const uint8_t *gpassed = NULL;
            uint16_t rlen = 0;
            arachnae_status generic = parse_burst(frame, len, own, fz_roles[r].check, gbuf, fz_roles[r].rx_max, &gpassed);
            arachnae_status own_rx = fz_roles[r].rx(own, frame, len, rbuf, &rlen);
            if (own_rx != generic)
                fail("the role's parser and the generic parser disagree", (int)own_rx, (int)generic);
            if (gpassed != NULL && (rlen != len || memcmp(rbuf, frame, len) != 0))
                fail("the role's parser passed other bytes", (int)rlen, (int)len);
        }
        if (passed == NULL)
            continue;
        disp = fz_roles[r].dispatch(own, passed);
        /* the skeleton answers STATUS_REQ with what the (empty) behaviour filled in,
         * which may be out of range (RANGE from the reply's check); all else is delivered */
        if (disp != ARACHNAE_OK && !(frame[ARACHNAE_FRAME_OPCODE] == ARACHNAE_OP_STATUS_REQ && disp == ARACHNAE_RANGE))
            fail("dispatch refuses a frame its parser passed", (int)disp, (int)ARACHNAE_OK);
    }

    /* 4. payload decoders on an exact-size heap copy of the claimed payload */
    if (len >= ARACHNAE_FRAME_OVERHEAD) {
        uint8_t plen = frame[ARACHNAE_FRAME_LENGTH];
        uint16_t avail = (uint16_t)(len - ARACHNAE_FRAME_OVERHEAD);
        uint8_t *payload;
        if (plen > avail)
            plen = (uint8_t)avail;
        payload = (uint8_t *)malloc(plen ? plen : 1u);
        if (payload == NULL)
            return;
        memcpy(payload, frame + ARACHNAE_FRAME_PAYLOAD, plen);
        (void)arachnae_decode_payload(frame[ARACHNAE_FRAME_OPCODE], payload, plen, &m);
        (void)arachnae_payload_check(frame[ARACHNAE_FRAME_OPCODE], payload, plen);
        free(payload);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    uint16_t len;
    uint8_t *fixed;
    if (size < 1u || size > 1u + ARACHNAE_MAX_FRAME + 8u)
        return 0;
    len = (uint16_t)(size - 1u);
    /* exact-size heap copies: ASan reports any read past the frame */
    fixed = (uint8_t *)malloc(len ? len : 1u);
    if (fixed == NULL)
        return 0;
    memcpy(fixed, data + 1, len);
    check_frame(data[0], fixed, len);
    if (len >= ARACHNAE_FRAME_CRC_SIZE) {
        uint16_t crc = arachnae_crc16(fixed, (uint16_t)(len - ARACHNAE_FRAME_CRC_SIZE));
        fixed[len - 2u] = (uint8_t)(crc >> 8);
        fixed[len - 1u] = (uint8_t)(crc & 0xFFu);
        check_frame(data[0], fixed, len);
    }
    free(fixed);
    return 0;
}
