/*
 * Drives the TPSC, JAC(1,1) and MMC skeletons with frames from a file.
 * Usage: skeleton_test FILE, lines "<role> <frame_hex>". For each frame it prints
 *   parser <STATUS>     the byte-at-a-time parser with the role's buffer size and payload check
 *   call ... / send ... what the behaviour callbacks saw and what the skeleton sent
 *   status <STATUS>     the verdict of the parser with the role's payload check and a buffer of any frame's
 *                       size, or, for a frame it passed, the skeleton's dispatch result (dispatch takes
 *                       only frames the parser passed: it does not check them again, issue 15)
 * Then "accepts <role> <addresses...>": the own addresses node_init accepts.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "arachnae_generic.h"
#include "node_jac.h"
#include "node_mmc.h"
#include "node_tpsc.h"

static uint16_t parse_hex(const char *s, uint8_t *out, uint16_t cap)
{
    uint16_t n = 0;
    while (s[0] != '\0' && s[1] != '\0' && n < cap) {
        unsigned v;
        if (sscanf(s, "%2x", &v) != 1)
            break;
        out[n++] = (uint8_t)v;
        s += 2;
    }
    return n;
}

/* The parser's verdict over one burst (feed every byte, then the gap); the frame it passed, if any, in *out. */
static arachnae_status run_parser(const uint8_t *frame, uint16_t n, uint16_t own, arachnae_payload_check_fn check,
                                  uint16_t cap, uint8_t *buf, const uint8_t **out)
{
    arachnae_parser p;
    arachnae_status verdict = ARACHNAE_NONE, st;
    uint16_t i, len = 0;
    arachnae_parser_init(&p, buf, cap, own, check);
    for (i = 0; i < n; i++)
        if ((st = arachnae_parser_feed(&p, frame[i])) != ARACHNAE_NONE)
            verdict = st;
    if ((st = arachnae_parser_gap(&p)) != ARACHNAE_NONE)
        verdict = st;
    *out = (verdict == ARACHNAE_OK) ? arachnae_parser_frame(&p, &len) : NULL;
    if (verdict == ARACHNAE_OK && (*out == NULL || len != n))
        return ARACHNAE_NONE;   /* the parser says OK but holds no such frame: a bug, printed as NONE */
    return verdict;
}

/* The role's own parser (node_<role>.c) over one burst, as run_parser: what a node image runs (issue 15). */
#define ROLE_PARSER(r, R)                                                                            \
    static arachnae_status r##_parse(const uint8_t *frame, uint16_t n, uint8_t own)                  \
    {                                                                                                \
        r##_rx p = R##_RX_INIT(own);                                                                 \
        arachnae_status verdict = ARACHNAE_NONE, st;                                                 \
        uint16_t i, len = 0;                                                                         \
        (void)own;                                                                                   \
        for (i = 0; i < n; i++)                                                                      \
            if ((st = r##_rx_feed(&p, frame[i])) != ARACHNAE_NONE)                                   \
                verdict = st;                                                                        \
        if ((st = r##_rx_gap(&p)) != ARACHNAE_NONE)                                                  \
            verdict = st;                                                                            \
        if ((verdict == ARACHNAE_OK) != (r##_rx_frame(&p, &len) != NULL) || (verdict == ARACHNAE_OK && len != n)) \
            return ARACHNAE_NONE;   /* the verdict and the held frame disagree: a bug, printed as NONE */ \
        return verdict;                                                                              \
    }
ROLE_PARSER(tpsc, TPSC)
ROLE_PARSER(jac, JAC)
ROLE_PARSER(mmc, MMC)

int main(int argc, char **argv)
{
    char line[1024], role[16], hex[700];
    uint8_t frame[ARACHNAE_MAX_FRAME], buf[ARACHNAE_MAX_FRAME];
    const uint8_t *ok;
    tpsc_node tpsc;
    jac_node jac;
    mmc_node mmc;
    unsigned a;
    FILE *fp;
    if (argc != 2 || (fp = fopen(argv[1], "r")) == NULL)
        return 2;
    if (tpsc_node_init(&tpsc, ARACHNAE_ADDR_TPSC, NULL) != ARACHNAE_OK ||
        jac_node_init(&jac, ARACHNAE_ADDR_JAC_1_1, NULL) != ARACHNAE_OK ||
        mmc_node_init(&mmc, ARACHNAE_ADDR_MMC, NULL) != ARACHNAE_OK)
        return 3;
    while (fgets(line, sizeof line, fp) != NULL) {
        uint16_t n;
        arachnae_status st;
        if (sscanf(line, "%15s %699s", role, hex) != 2)
            continue;
        n = parse_hex(hex, frame, sizeof frame);
        if (strcmp(role, "tpsc") == 0) {
            if (run_parser(frame, n, tpsc.address, tpsc_payload_check, ARACHNAE_RX_MAX_TPSC, buf, &ok) != tpsc_parse(frame, n, tpsc.address))
                printf("parsers disagree\n");
            printf("parser %s\n", arachnae_status_name(tpsc_parse(frame, n, tpsc.address)));
            st = run_parser(frame, n, tpsc.address, tpsc_payload_check, sizeof buf, buf, &ok);
            if (ok != NULL)
                st = tpsc_dispatch(&tpsc, ok);
        } else if (strcmp(role, "jac") == 0) {
            if (run_parser(frame, n, jac.address, jac_payload_check, ARACHNAE_RX_MAX_JAC, buf, &ok) != jac_parse(frame, n, jac.address))
                printf("parsers disagree\n");
            printf("parser %s\n", arachnae_status_name(jac_parse(frame, n, jac.address)));
            st = run_parser(frame, n, jac.address, jac_payload_check, sizeof buf, buf, &ok);
            if (ok != NULL)
                st = jac_dispatch(&jac, ok);
        } else {
            if (run_parser(frame, n, mmc.address, mmc_payload_check, ARACHNAE_RX_MAX_MMC, buf, &ok) != mmc_parse(frame, n, mmc.address))
                printf("parsers disagree\n");
            printf("parser %s\n", arachnae_status_name(mmc_parse(frame, n, mmc.address)));
            st = run_parser(frame, n, mmc.address, mmc_payload_check, sizeof buf, buf, &ok);
            if (ok != NULL)
                st = mmc_dispatch(&mmc, ok);
        }
        printf("status %s\n", arachnae_status_name(st));
    }
    fclose(fp);
    printf("accepts jac");
    for (a = 0; a < 256u; a++) {
        jac_node probe;
        if (jac_node_init(&probe, (uint8_t)a, NULL) == ARACHNAE_OK)
            printf(" %02x", a);
    }
    printf("\n");
    return 0;
}
