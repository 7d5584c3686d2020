/*
 * IRRC behaviour (seed 3.2.13): three infrared beams (left, centre, right), measured on
 * the node's own clock with the three-plus-three rule; UNRELIABLE when the second set
 * spreads too; SET_ALARM: an object closer than the limit on any beam is reported with
 * DATA_RDY; FREE_RUN announces every measurement. Same logic as behaviours/sensors.py IRRC.
 */
#include "role_config.h"
#include "hal.h"
#include "lib/sensor.h"

enum { BEAMS = 3 };

typedef struct {
    fw_slave slave;
    fw_alarm alarms[BEAMS];
    int16_t latest[BEAMS];
    uint8_t status, free_run, near;
    uint16_t next_measure, second_sets;
} irrc_state;

static irrc_state st;

static void declare(uint8_t status, uint16_t now)
{
    fw_declare(&st.slave, &st.status, status, st.free_run, now);
}

static void measure(uint16_t now)
{
    int16_t got[BEAMS];
    uint8_t near, b, ok;
    int16_t nearest;
    fw_debug[FW_DBG_MEASUREMENTS]++;
    ok = fw_three_plus_three(HAL_SAMPLE_IR, 0, BEAMS, 0, TUNING_IRRC_SPREAD_RAW, got, &st.second_sets, 0);
    fw_debug[FW_DBG_SECOND_SETS] = (int16_t)st.second_sets;
    if (!ok) {
        declare(ARACHNAE_RANGE_STATUS_UNRELIABLE, now);
        return;                              /* CHOICE: an unreliable measurement never replaces the last value */
    }
    nearest = got[0];
    for (b = 0; b < BEAMS; b++) {
        st.latest[b] = got[b];
        if (got[b] < nearest)
            nearest = got[b];
    }
    /* telemetry: a new object this close ahead is a stimulus (5.2 latency); milli-cm against mm * 100 */
    near = (uint8_t)(arachnae_xmit_data_irrc_center_to_milli((uint8_t)nearest) < (int32_t)TUNING_IRRC_NEAR_MM * 100);
    if (near && !st.near)
        hal_note(HAL_NOTE_STIMULUS, HAL_STIMULUS_IR);
    st.near = near;
    if (st.status == ARACHNAE_RANGE_STATUS_IN_ORDER)
        (void)fw_check_alarms(st.alarms, got, BEAMS, TUNING_ALARM_REARM_RAW, &st.slave, now);
    if (st.free_run)
        fw_announce(&st.slave, now, 0);     /* FREE_RUN: announce data with DATA_RDY */
}

void irrc_send(irrc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    hal_send(frame, len);
}

void irrc_on_init(irrc_node *node, const arachnae_header *h)
{
    uint8_t b;
    (void)node;
    (void)h;
    st.status = ARACHNAE_RANGE_STATUS_IN_ORDER;   /* CHOICE: initialised again, the sensor trusts itself */
    fw_debug[FW_DBG_STATUS] = st.status;
    for (b = 0; b < BEAMS; b++)
        st.alarms[b].set = 0;
}

void irrc_on_status_req(irrc_node *node, const arachnae_header *h, arachnae_status_ack_range_t *reply)
{
    (void)node;
    (void)h;
    reply->status = st.status;
}

void irrc_on_do_measure(irrc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
    measure(hal_ms());
}

void irrc_on_free_run(irrc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
    st.free_run = 1;
}

void irrc_on_set_alarm_irrc(irrc_node *node, const arachnae_header *h, const arachnae_set_alarm_irrc_t *msg)
{
    /* seed 3.2.13: report on its own when an object comes closer than the limit (any beam);
       the limit through physical units into the data field's steps (behaviours.sensors.limit_in) */
    uint8_t raw = 0, b;
    (void)node;
    (void)h;
#if FW_ALARM_LIMIT_IS_DATA_RAW
    raw = msg->limit;                        /* one encoding for both (spec; checked by roles.py) */
#else
    if (arachnae_xmit_data_irrc_center_from_milli(arachnae_set_alarm_irrc_limit_to_milli(msg->limit), &raw)
        != ARACHNAE_OK)
        raw = UINT8_MAX;                     /* beyond the measuring range: saturates as the front end does */
#endif
    for (b = 0; b < BEAMS; b++)
        fw_alarm_set(&st.alarms[b], (int16_t)raw, FW_BELOW);
}

/* seed 3.2.11: the skeleton answers with XMIT_DATA_IRRC what this fills in (spec reply_to) */
uint8_t irrc_on_xmit_data(irrc_node *node, const arachnae_header *h, arachnae_xmit_data_irrc_t *m)
{
    (void)h;
    (void)node;
    fw_fetched(&st.slave);
    m->left = (uint8_t)st.latest[0];
    m->center = (uint8_t)st.latest[1];
    m->right = (uint8_t)st.latest[2];
    return 1;
}

void fw_behaviour_init(void *vnode)
{
    irrc_node *node = (irrc_node *)vnode;
    uint8_t b;
    fw_slave_init(&st.slave, node->address);
    st.status = ARACHNAE_RANGE_STATUS_IN_ORDER;
    for (b = 0; b < BEAMS; b++)
        st.latest[b] = UINT8_MAX;           /* nothing seen yet: the top of the range */
    st.next_measure = hal_ms();
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    (void)vnode;
    if (fw_every(&st.next_measure, now, TUNING_IRRC_MEASURE_MS))
        measure(now);
    fw_slave_poll(&st.slave, now);
}
