/*
 * A TPSC firmware image in miniature: UART bytes (stdin here) into the role's parser,
 * complete frames into the skeleton. test_c_codec.py links it with
 * --gc-sections and checks that only what the TPSC role uses is in the image
 * (issue 6 measures per-role flash the same way).
 */
#include <stdio.h>

#include "node_tpsc.h"

void tpsc_send(tpsc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    fwrite(frame, 1, len, stdout);
}
void tpsc_on_init(tpsc_node *node, const arachnae_header *h) { (void)node; (void)h; }
void tpsc_on_status_req(tpsc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER;
}
uint8_t tpsc_on_xmit_data(tpsc_node *node, const arachnae_header *h, arachnae_xmit_data_tpsc_t *reply)
{
    (void)node;
    (void)h;
    reply->contact = ARACHNAE_TPSC_CONTACT_OBJ_BOTH;
    return 1;
}

int main(void)
{
    tpsc_rx parser = TPSC_RX_INIT(ARACHNAE_ADDR_TPSC);
    tpsc_node node;
    int c;
    if (tpsc_node_init(&node, ARACHNAE_ADDR_TPSC, NULL) != ARACHNAE_OK)
        return 1;
    while ((c = getchar()) != EOF) {
        /* a real UART ISR calls feed(); an idle-gap timer calls gap() */
        if (tpsc_rx_feed(&parser, (uint8_t)c) == ARACHNAE_OK) {
            uint16_t len = 0;
            const uint8_t *frame = tpsc_rx_frame(&parser, &len);
            if (frame != NULL)
                (void)tpsc_dispatch(&node, frame);
        }
    }
    (void)tpsc_rx_gap(&parser);
    return 0;
}
