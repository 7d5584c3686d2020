/*
 * TPSC behaviour (seed 3.2.12): two whisker switches; the TPSC always initiates.
 * On a new contact it sends DATA_RDY to the SPU and answers the SPU's XMIT_DATA
 * with XMIT_DATA_TPSC (OBJ_LEFT 0x10, OBJ_RIGHT 0x20, OBJ_BOTH 0x40).
 * Same behaviour as sim2d/behaviours/sensor_nodes.py TPSC, for the SIL run.
 */
#include "role_config.h"
#include "hal.h"

#define SCAN_MS 20u        /* switch scan / debounce period (sim2d: tick_period 0.02) */
#define STIMULUS_MS 2u     /* width of the test-point pulse marking a detected contact */

enum { TX_IDLE, TX_WAIT_ECHO, TX_BACKOFF };

typedef struct {
    uint8_t contact;       /* contact code of the last scan */
    uint8_t latched;       /* contact that caused the pending DATA_RDY, until fetched */
    uint8_t data_rdy;      /* 1 while a DATA_RDY waits to get through */
    uint8_t tx;
    uint16_t last_scan, backoff_until, pulse_until;
    uint8_t pulse;
} tpsc_state;

static tpsc_state st;

static uint8_t contact_code(uint8_t inputs)
{
    /* seed 3.2.12: OBJ_BOTH when both whiskers touch, else the side that touched */
    if ((inputs & 0x03u) == 0x03u)
        return ARACHNAE_TPSC_CONTACT_OBJ_BOTH;
    if (inputs & 0x01u)
        return ARACHNAE_TPSC_CONTACT_OBJ_LEFT;
    if (inputs & 0x02u)
        return ARACHNAE_TPSC_CONTACT_OBJ_RIGHT;
    return 0;
}

void tpsc_send(tpsc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    hal_send(frame, len);
}

void tpsc_on_init(tpsc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
    st.latched = 0;
    st.data_rdy = 0;
    st.tx = TX_IDLE;
}

void tpsc_on_status_req(tpsc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER; /* seed 3.2.12: the TPSC always answers IN_ORDER */
}

void tpsc_on_xmit_data(tpsc_node *node, const arachnae_header *h)
{
    arachnae_xmit_data_tpsc_t m;
    uint8_t out[ARACHNAE_XMIT_DATA_TPSC_FRAME_MAX];
    uint16_t n = 0;
    if (h->dst == ARACHNAE_ADDR_BROADCAST)
        return;
    m.contact = st.latched ? st.latched : st.contact;
    if (arachnae_xmit_data_tpsc_build(&m, h->src, node->address, out, sizeof out, &n) == ARACHNAE_OK)
        tpsc_send(node, out, n);
    st.latched = 0;
    /* a DATA_RDY whose echo was corrupt is still resent, as in the Python node */
}

static void send_data_rdy(tpsc_node *node)
{
    uint8_t out[ARACHNAE_DATA_RDY_FRAME_MAX];
    uint16_t n = 0;
    if (arachnae_data_rdy_build(FW_MASTER_ADDRESS, node->address, out, sizeof out, &n) == ARACHNAE_OK) {
        tpsc_send(node, out, n);
        st.tx = TX_WAIT_ECHO;
    }
}

void fw_behaviour_init(void *node)
{
    (void)node;
    st.contact = contact_code(hal_inputs());
    st.tx = TX_IDLE;
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    tpsc_node *node = (tpsc_node *)vnode;
    if (st.pulse && (int16_t)(now - st.pulse_until) >= 0) {
        st.pulse = 0;
        hal_test_point(0);
    }
    if ((uint16_t)(now - st.last_scan) >= SCAN_MS) {
        uint8_t c = contact_code(hal_inputs());
        st.last_scan = now;
        if (c != 0u && c != st.contact) {
            st.latched = c;
            st.data_rdy = 1;               /* seed 3.2.12: the TPSC always initiates */
            st.pulse = 1;
            st.pulse_until = (uint16_t)(now + STIMULUS_MS);
            hal_test_point(1);
        }
        st.contact = c;
    }
    switch (st.tx) {
    case TX_IDLE:
        if (st.data_rdy && hal_line_idle())
            send_data_rdy(node);
        break;
    case TX_WAIT_ECHO:
        switch (hal_echo_status()) {
        case HAL_ECHO_OK:
            st.data_rdy = 0;
            st.tx = TX_IDLE;
            break;
        case HAL_ECHO_CORRUPT:
            /* seed 3.2.2 + spec arbitration address_backoff: wait (rank + 1) slots, then resend */
            st.backoff_until = (uint16_t)(now + (FW_BACKOFF_RANK + 1u) * FW_BACKOFF_SLOT_US / 1000u);
            st.tx = TX_BACKOFF;
            break;
        default:
            break;
        }
        break;
    default:
        if ((int16_t)(now - st.backoff_until) >= 0) {
            st.tx = TX_IDLE;
            if (st.data_rdy && hal_line_idle())
                send_data_rdy(node);
        }
        break;
    }
}
