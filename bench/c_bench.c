/*
 * Decode throughput of the generated C codec (issue 2): whole-frame check (length,
 * CRC-16, address) plus payload decode of typical frames, against references in
 * the same run. Prints figures only; bench/c_bench.py builds and runs it.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "arachnae.h"
#include "arachnae_generic.h"

#define NFRAMES 1024u

static uint8_t usrc[NFRAMES][ARACHNAE_XMIT_DATA_USRC_FRAME_MAX];
static uint8_t move[NFRAMES][ARACHNAE_MOVE_RELAYED_FRAME_MAX];
static uint16_t usrc_len, move_len;
static volatile uint32_t sink;

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* 256-entry table CRC, the usual host-side implementation (reference only). */
static uint16_t table[256];
static void make_table(void)
{
    unsigned i, b;
    for (i = 0; i < 256u; i++) {
        uint16_t c = (uint16_t)(i << 8);
        for (b = 0; b < 8u; b++)
            c = (uint16_t)((c & 0x8000u) ? ((unsigned)(uint16_t)(c << 1) ^ 0x1021u) : (unsigned)(uint16_t)(c << 1));
        table[i] = c;
    }
}
static uint16_t crc_table(const uint8_t *d, uint16_t n)
{
    uint16_t c = ARACHNAE_CRC_INIT;
    uint16_t i;
    for (i = 0; i < n; i++)
        c = (uint16_t)((unsigned)(uint16_t)(c << 8) ^ table[((c >> 8) ^ d[i]) & 0xFFu]);
    return c;
}

/* ---- the measured loops: one pass over NFRAMES frames ---- */
static uint32_t pass_usrc_decode(void)
{
    uint32_t acc = 0;
    unsigned i;
    for (i = 0; i < NFRAMES; i++) {
        const uint8_t *f = usrc[i];
        arachnae_xmit_data_usrc_t m;
        if (arachnae_frame_check(f, usrc_len, ARACHNAE_ADDR_SPU) == ARACHNAE_OK &&
            arachnae_xmit_data_usrc_decode(f + ARACHNAE_FRAME_PAYLOAD, f[ARACHNAE_FRAME_LENGTH], &m) == ARACHNAE_OK)
            acc += (uint32_t)m.distance + m.angle;
    }
    return acc;
}

static uint32_t pass_move_decode(void)
{
    uint32_t acc = 0;
    unsigned i;
    for (i = 0; i < NFRAMES; i++) {
        const uint8_t *f = move[i];
        arachnae_move_relayed_t m;
        if (arachnae_frame_check(f, move_len, ARACHNAE_ADDR_MMC) == ARACHNAE_OK &&
            arachnae_move_relayed_decode(f + ARACHNAE_FRAME_PAYLOAD, f[ARACHNAE_FRAME_LENGTH], &m) == ARACHNAE_OK)
            acc += (uint32_t)m.address + m.mov_cmd;
    }
    return acc;
}

static uint32_t pass_usrc_generic(void)
{
    uint32_t acc = 0;
    unsigned i;
    for (i = 0; i < NFRAMES; i++) {
        arachnae_message m;
        if (arachnae_frame_decode(usrc[i], usrc_len, ARACHNAE_ADDR_SPU, NULL, &m) == ARACHNAE_OK)
            acc += (uint32_t)m.u.xmit_data_usrc.distance + m.u.xmit_data_usrc.angle;
    }
    return acc;
}

static uint32_t pass_usrc_parser(void)
{
    uint8_t buf[ARACHNAE_MAX_FRAME];
    arachnae_parser p;
    uint32_t acc = 0;
    unsigned i, j;
    arachnae_parser_init(&p, buf, sizeof buf, ARACHNAE_ADDR_SPU, arachnae_payload_check);
    for (i = 0; i < NFRAMES; i++) {
        for (j = 0; j < usrc_len; j++)
            if (arachnae_parser_feed(&p, usrc[i][j]) == ARACHNAE_OK)
                acc++;
        (void)arachnae_parser_gap(&p);
    }
    return acc;
}

/* reference: copy the frame out and CRC it with the same generated CRC, nothing else */
static uint32_t pass_ref_memcpy_crc(void)
{
    uint32_t acc = 0;
    unsigned i;
    for (i = 0; i < NFRAMES; i++) {
        uint8_t copy[ARACHNAE_XMIT_DATA_USRC_FRAME_MAX];
        memcpy(copy, usrc[i], usrc_len);
        acc += arachnae_crc16(copy, (uint16_t)(usrc_len - ARACHNAE_FRAME_CRC_SIZE)) + copy[4];
    }
    return acc;
}

/* reference: copy the frame out and CRC it with a 256-entry table */
static uint32_t pass_ref_memcpy_table(void)
{
    uint32_t acc = 0;
    unsigned i;
    for (i = 0; i < NFRAMES; i++) {
        uint8_t copy[ARACHNAE_XMIT_DATA_USRC_FRAME_MAX];
        memcpy(copy, usrc[i], usrc_len);
        acc += crc_table(copy, (uint16_t)(usrc_len - ARACHNAE_FRAME_CRC_SIZE)) + copy[4];
    }
    return acc;
}

/* frames per second: best of 5 runs of ~0.2 s each */
static double measure(uint32_t (*pass)(void))
{
    double best = 0.0;
    int run;
    for (run = 0; run < 5; run++) {
        unsigned long passes = 0;
        double t0 = now(), t;
        do {
            sink += pass();
            passes++;
        } while ((t = now() - t0) < 0.2);
        if ((double)passes * NFRAMES / t > best)
            best = (double)passes * NFRAMES / t;
    }
    return best;
}

int main(void)
{
    unsigned i;
    double ref, ref_table, fps;
    make_table();
    for (i = 0; i < NFRAMES; i++) {
        arachnae_xmit_data_usrc_t u;
        arachnae_move_relayed_t mv;
        u.distance = (uint8_t)(i & 0xFFu);
        u.angle = (uint16_t)(i % 360u);
        mv.address = ARACHNAE_ADDR_NP3;
        mv.mov_cmd = (uint8_t)(i % 10u);
        mv.param = 0;
        if (arachnae_xmit_data_usrc_build(&u, ARACHNAE_ADDR_SPU, ARACHNAE_ADDR_USRC, usrc[i], sizeof usrc[i], &usrc_len) != ARACHNAE_OK ||
            arachnae_move_relayed_build(&mv, ARACHNAE_ADDR_MMC, ARACHNAE_ADDR_MCP, move[i], sizeof move[i], &move_len) != ARACHNAE_OK) {
            printf("setup failed\n");
            return 1;
        }
    }
    if (pass_usrc_decode() == 0u || pass_usrc_parser() != NFRAMES || crc_table(usrc[0], 7) != arachnae_crc16(usrc[0], 7)) {
        printf("self-check failed\n");
        return 1;
    }
    ref = measure(pass_ref_memcpy_crc);
    ref_table = measure(pass_ref_memcpy_table);
    printf("%-52s %8.1f M frames/s\n", "reference: memcpy + generated CRC (9-byte frame)", ref / 1e6);
    printf("%-52s %8.1f M frames/s\n", "reference: memcpy + 256-entry table CRC", ref_table / 1e6);
    fps = measure(pass_usrc_decode);
    printf("%-52s %8.1f M frames/s  (%.2f x ref, %.2f x table ref)\n", "XMIT_DATA_USRC: frame_check + decode", fps / 1e6,
           fps / ref, fps / ref_table);
    fps = measure(pass_move_decode);
    printf("%-52s %8.1f M frames/s  (%.2f x ref)\n", "MOVE_RELAYED: frame_check + decode (8-byte frame)", fps / 1e6, fps / ref);
    fps = measure(pass_usrc_generic);
    printf("%-52s %8.1f M frames/s  (%.2f x ref)\n", "XMIT_DATA_USRC: generic arachnae_frame_decode", fps / 1e6, fps / ref);
    fps = measure(pass_usrc_parser);
    printf("%-52s %8.1f M frames/s  (%.2f x ref)\n", "XMIT_DATA_USRC: byte parser (feed x9 + gap)", fps / 1e6, fps / ref);
    return 0;
}
