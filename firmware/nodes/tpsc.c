/*
 * TPSC behaviour (seed 3.2.12): two whisker switches; the TPSC always initiates.
 * On a new contact it sends DATA_RDY to the SPU (at most once per the reflex's
 * min_interval, spec reflexes / seed 5.2; a contact sooner than that goes with the
 * next request) and answers the SPU's XMIT_DATA with XMIT_DATA_TPSC (OBJ_LEFT 0x10,
 * OBJ_RIGHT 0x20, OBJ_BOTH 0x40). Same behaviour as behaviours/sensors.py TPSC.
 */
#include "role_config.h"
#include "hal.h"
#include "lib/sensor.h"

#define STIMULUS_MS 2u     /* width of the test-point pulse marking a detected contact */

typedef struct {
    fw_slave slave;
    uint8_t contact;       /* contact code of the last scan */
    uint8_t latched;       /* contact that caused the pending DATA_RDY, until fetched */
    uint8_t requested, held, pulse;
    uint16_t last_scan, requested_at, pulse_until;
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

/* DATA_RDY, at most once per the reflex's min_interval (spec reflexes): a contact sooner than that
   is latched and goes with the next request; the STOP of the last one is already on its way (5.2).
   More than min_interval ticks: a millisecond tick began up to 1 ms after the last request */
static void request(uint16_t now)
{
    if (st.requested && (uint16_t)(now - st.requested_at) <= FW_REFLEX_MIN_INTERVAL_MS) {
        st.held = 1;
        return;
    }
    st.requested = 1;
    st.requested_at = now;
    hal_note(HAL_NOTE_REFLEX, 0);          /* debug port: raised now (tracecheck reflex_rate) */
    fw_announce(&st.slave, now, 1);
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
}

void tpsc_on_status_req(tpsc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER; /* seed 3.2.12: the TPSC always answers IN_ORDER */
}

/* seed 3.2.11: the skeleton answers with XMIT_DATA_TPSC what this fills in (spec reply_to) */
uint8_t tpsc_on_xmit_data(tpsc_node *node, const arachnae_header *h, arachnae_xmit_data_tpsc_t *m)
{
    (void)h;
    (void)node;
    m->contact = st.latched ? st.latched : st.contact;
    st.latched = 0;
    return 1;
}

void fw_behaviour_init(void *vnode)
{
    fw_slave_init(&st.slave, ((tpsc_node *)vnode)->address);
    st.contact = contact_code(hal_inputs());
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    (void)vnode;
    if (st.pulse && (int16_t)(now - st.pulse_until) >= 0) {
        st.pulse = 0;
        hal_test_point(0);
    }
    if ((uint16_t)(now - st.last_scan) >= TUNING_TPSC_SCAN_MS) {
        uint8_t c = contact_code(hal_inputs());
        st.last_scan = now;
        if (c != 0u && c != st.contact) {
            st.latched = c;
            st.pulse = 1;                  /* the stimulus, on the test point */
            st.pulse_until = (uint16_t)(now + STIMULUS_MS);
            hal_test_point(1);
            request(now);                  /* seed 3.2.12: the TPSC always initiates */
        }
        st.contact = c;
    }
    if (st.held && (uint16_t)(now - st.requested_at) > FW_REFLEX_MIN_INTERVAL_MS) {
        st.held = 0;
        if (st.latched)
            request(now);
    }
    fw_slave_poll(&st.slave, now);
}
