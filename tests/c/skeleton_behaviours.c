/*
 * Minimal example behaviours for three node skeletons (TPSC, JAC, MMC), as a
 * firmware engineer would write them in firmware/nodes/<role>.c. Here every
 * callback prints what it got, so tests/c/test_c_codec.py can check that the
 * skeleton called the right one with the right values, and `send` prints the
 * frames the skeleton transmits.
 */
#include <stdio.h>

#include "node_jac.h"
#include "node_mmc.h"
#include "node_tpsc.h"

static void print_frame(const char *role, const uint8_t *frame, uint16_t len)
{
    uint16_t i;
    printf("send %s ", role);
    for (i = 0; i < len; i++)
        printf("%02x", frame[i]);
    printf("\n");
}

/* ---- TPSC (seed 3.2.12) ---- */
void tpsc_send(tpsc_node *node, const uint8_t *frame, uint16_t len) { (void)node; print_frame("tpsc", frame, len); }
void tpsc_on_init(tpsc_node *node, const arachnae_header *h) { (void)node; printf("call tpsc_on_init src=%u\n", h->src); }
void tpsc_on_status_req(tpsc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER; /* seed 3.2.12: the TPSC always answers IN_ORDER */
}
/* the first call answers OBJ_LEFT, every later one a reserved bit (0x01): the skeleton must refuse to send that */
uint8_t tpsc_on_xmit_data(tpsc_node *node, const arachnae_header *h, arachnae_xmit_data_tpsc_t *reply)
{
    static uint8_t calls;
    (void)node;
    printf("call tpsc_on_xmit_data src=%u\n", h->src);
    reply->contact = calls++ ? 0x01u : ARACHNAE_TPSC_CONTACT_OBJ_LEFT;
    return 1;
}

/* ---- JAC (seed 3.2.18) ---- */
void jac_send(jac_node *node, const uint8_t *frame, uint16_t len) { (void)node; print_frame("jac", frame, len); }
void jac_on_init(jac_node *node, const arachnae_header *h) { (void)node; printf("call jac_on_init src=%u\n", h->src); }
void jac_on_status_req(jac_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_OUT_OF_ORDER;
}
void jac_on_joint_target(jac_node *node, const arachnae_header *h, const arachnae_joint_target_t *msg)
{
    (void)node;
    printf("call jac_on_joint_target src=%u angle=%d speed=%u\n", h->src, msg->angle, msg->speed);
}
void jac_on_joint_poll(jac_node *node, const arachnae_header *h) { (void)node; printf("call jac_on_joint_poll src=%u\n", h->src); }

/* ---- MMC (seed 3.2.4) ---- */
void mmc_send(mmc_node *node, const uint8_t *frame, uint16_t len) { (void)node; print_frame("mmc", frame, len); }
void mmc_on_init(mmc_node *node, const arachnae_header *h) { (void)node; printf("call mmc_on_init src=%u\n", h->src); }
void mmc_on_status_req(mmc_node *node, const arachnae_header *h, arachnae_status_ack_mmc_t *reply)
{
    (void)node;
    (void)h;
    reply->gait = ARACHNAE_GAIT_TRIPOD;
    reply->direction = ARACHNAE_DIRECTION_FORWARD;
    reply->leg = 0;
    reply->error = ARACHNAE_MMC_ERROR_NONE;
}
void mmc_on_id_ack(mmc_node *node, const arachnae_header *h, const arachnae_id_ack_t *msg)
{
    (void)node;
    printf("call mmc_on_id_ack src=%u address=%u\n", h->src, msg->address);
}
void mmc_on_status_ack_order(mmc_node *node, const arachnae_header *h, const arachnae_status_ack_order_t *msg)
{
    (void)node;
    printf("call mmc_on_status_ack_order src=%u status=%u\n", h->src, msg->status);
}
/* POST not done yet: no reply now (seed 6.3; the behaviour sends POST_REPORT when it is) */
uint8_t mmc_on_post_query(mmc_node *node, const arachnae_header *h, arachnae_post_report_t *reply)
{
    (void)node;
    (void)reply;
    printf("call mmc_on_post_query src=%u\n", h->src);
    return 0;
}
void mmc_on_post_report(mmc_node *node, const arachnae_header *h, const arachnae_post_report_t *msg)
{
    (void)node;
    printf("call mmc_on_post_report src=%u missing_count=%u\n", h->src, msg->missing_count);
}
void mmc_on_move_relayed(mmc_node *node, const arachnae_header *h, const arachnae_move_relayed_t *msg)
{
    (void)node;
    printf("call mmc_on_move_relayed src=%u address=%u mov_cmd=%u param=%u\n", h->src, msg->address, msg->mov_cmd,
           msg->param);
}
void mmc_on_leg_report(mmc_node *node, const arachnae_header *h, const arachnae_leg_report_t *msg)
{
    (void)node;
    printf("call mmc_on_leg_report src=%u flags=%u x=%d y=%d z=%d servo_temp=%d\n", h->src, msg->flags, msg->x, msg->y,
           msg->z, msg->servo_temp);
}
