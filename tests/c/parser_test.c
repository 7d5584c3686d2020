/*
 * Byte-at-a-time parser scenarios on one valid frame (hex on argv[1], size argv[2]).
 * Prints one line per scenario with every status other than NONE, in order;
 * tests/c/test_c_codec.py compares them with what the contract says.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "arachnae_generic.h"

static uint8_t frame[ARACHNAE_MAX_FRAME + 1];
static uint16_t n;

static void feed(arachnae_parser *p, const uint8_t *b, uint16_t len, int *first_at)
{
    uint16_t i;
    for (i = 0; i < len; i++) {
        arachnae_status st = arachnae_parser_feed(p, b[i]);
        if (st != ARACHNAE_NONE) {
            printf(" %s", arachnae_status_name(st));
            if (first_at != NULL && *first_at == 0)
                *first_at = i + 1;
        }
    }
}

static void gap(arachnae_parser *p)
{
    arachnae_status st = arachnae_parser_gap(p);
    if (st != ARACHNAE_NONE)
        printf(" %s", arachnae_status_name(st));
}

int main(int argc, char **argv)
{
    uint8_t buf[ARACHNAE_MAX_FRAME];
    arachnae_parser p;
    const uint8_t *held;
    uint16_t i, held_len = 0;
    int at = 0;
    const uint8_t extra = 0x55;
    if (argc != 3)
        return 2;
    n = (uint16_t)atoi(argv[2]);
    for (i = 0; i < n; i++) {
        unsigned v;
        sscanf(argv[1] + 2 * i, "%2x", &v);
        frame[i] = (uint8_t)v;
    }

    printf("exact");
    arachnae_parser_init(&p, buf, n, ARACHNAE_ANY_ADDRESS, arachnae_payload_check);
    feed(&p, frame, n, NULL);
    gap(&p);
    printf("\n");

    printf("short");
    arachnae_parser_init(&p, buf, (uint16_t)(n - 1u), ARACHNAE_ANY_ADDRESS, arachnae_payload_check);
    feed(&p, frame, n, &at);
    gap(&p);
    printf(" at %d\n", at);

    printf("trailing");
    arachnae_parser_init(&p, buf, sizeof buf, ARACHNAE_ANY_ADDRESS, arachnae_payload_check);
    feed(&p, frame, n, NULL);
    feed(&p, &extra, 1, NULL);
    gap(&p);
    printf("\n");

    printf("two");
    arachnae_parser_init(&p, buf, sizeof buf, ARACHNAE_ANY_ADDRESS, arachnae_payload_check);
    feed(&p, frame, n, NULL);
    gap(&p);
    held = arachnae_parser_frame(&p, &held_len);  /* still there after the gap */
    if (held == NULL || held_len != n || memcmp(held, frame, n) != 0)
        printf(" held-frame-lost");
    feed(&p, frame, n, NULL);
    gap(&p);
    printf("\n");

    printf("cut");
    arachnae_parser_init(&p, buf, sizeof buf, ARACHNAE_ANY_ADDRESS, arachnae_payload_check);
    feed(&p, frame, (uint16_t)(n - 2u), NULL);
    gap(&p);
    if (arachnae_parser_frame(&p, &held_len) != NULL)
        printf(" truncated-frame-delivered");
    printf("\n");

    printf("recover");
    arachnae_parser_init(&p, buf, sizeof buf, ARACHNAE_ANY_ADDRESS, arachnae_payload_check);
    feed(&p, frame, n, NULL);
    feed(&p, &extra, 1, NULL);
    gap(&p);
    if (arachnae_parser_frame(&p, &held_len) != NULL)
        printf(" oversize-frame-delivered");
    feed(&p, frame, n, NULL);
    gap(&p);
    printf("\n");
    return 0;
}
