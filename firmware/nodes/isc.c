/*
 * ISC behaviour (seed 3.2.14): measures both inclinations continuously ("laufend") on
 * its own clock; SET_ALARM per axis: an inclination beyond the limit either way is
 * reported with DATA_RDY. Same logic as behaviours/sensors.py ISC.
 */
#include "role_config.h"
#include "hal.h"
#include "lib/sensor.h"

#if !FW_ALARM_LIMIT_IS_DATA_RAW
#error "the SET_ALARM limit and the data differ in encoding: convert as irrc.c does"
#endif

enum { AXES = 2 };

typedef struct {
    fw_slave slave;
    fw_alarm alarms[AXES];
    int16_t latest[AXES];
    uint16_t next_measure;
} isc_state;

static isc_state st;

void isc_send(isc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    hal_send(frame, len);
}

void isc_on_init(isc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
}

void isc_on_status_req(isc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER;
}

void isc_on_set_alarm_isc(isc_node *node, const arachnae_header *h, const arachnae_set_alarm_isc_t *msg)
{
    /* limit and data are both whole degrees (spec): no conversion; CHOICE (3.2.14): either way */
    (void)node;
    (void)h;
    if (msg->channel < AXES)
        fw_alarm_set(&st.alarms[msg->channel], msg->limit, FW_BEYOND);
}

/* seed 3.2.11: the skeleton answers with XMIT_DATA_ISC what this fills in (spec reply_to) */
uint8_t isc_on_xmit_data(isc_node *node, const arachnae_header *h, arachnae_xmit_data_isc_t *m)
{
    (void)h;
    (void)node;
    fw_fetched(&st.slave);
    m->longitudinal = (int8_t)st.latest[0];
    m->transverse = (int8_t)st.latest[1];
    return 1;
}

void fw_behaviour_init(void *vnode)
{
    fw_slave_init(&st.slave, ((isc_node *)vnode)->address);
    st.next_measure = hal_ms();
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    (void)vnode;
    if (fw_every(&st.next_measure, now, TUNING_ISC_MEASURE_MS)) {
        hal_sample(HAL_SAMPLE_INCLINATION, 0, st.latest, AXES);
        (void)fw_check_alarms(st.alarms, st.latest, AXES, TUNING_ALARM_REARM_RAW, &st.slave, now);
    }
    fw_slave_poll(&st.slave, now);
}
