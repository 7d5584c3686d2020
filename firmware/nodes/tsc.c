/*
 * TSC behaviour (seed 3.2.15): up to eight temperature probes, all measured on the node's
 * own clock; SET_ALARM per probe: hotter than the limit is reported with DATA_RDY; each
 * XMIT_DATA sends one probe, an alarmed probe first, else the probes in turn.
 * Same logic as behaviours/sensors.py TSC.
 */
#include "role_config.h"
#include "hal.h"
#include "lib/sensor.h"

#if !FW_ALARM_LIMIT_IS_DATA_RAW
#error "the SET_ALARM limit and the data differ in encoding: convert as irrc.c does"
#endif

#define PROBES_MAX 8u   /* seed 3.2.15: up to eight probes (XMIT_DATA_TSC channel 0..7) */

typedef struct {
    fw_slave slave;
    fw_alarm alarms[PROBES_MAX];
    int16_t latest[PROBES_MAX];
    uint8_t probes;                 /* probes fitted, 0 before the first measurement */
    uint8_t channel;                /* next probe sent in turn */
    uint8_t alarmed[PROBES_MAX];    /* alarmed probes not yet sent, oldest first */
    uint8_t n_alarmed;
    uint16_t next_measure;
} tsc_state;

static tsc_state st;

static void measure(uint16_t now)
{
    int16_t reply[1 + PROBES_MAX];
    uint8_t fired, ch, k, queued;
    hal_sample(HAL_SAMPLE_TEMPERATURES, 0, reply, (uint8_t)(1u + PROBES_MAX));   /* count, then each probe */
    st.probes = reply[0] > 0 && reply[0] <= (int16_t)PROBES_MAX ? (uint8_t)reply[0] : 0u;
    for (ch = 0; ch < st.probes; ch++)
        st.latest[ch] = reply[1 + ch];
    fired = fw_check_alarms(st.alarms, st.latest, st.probes, TUNING_ALARM_REARM_RAW, &st.slave, now);
    for (ch = 0; ch < st.probes; ch++) {
        if (!(fired & (1u << ch)))
            continue;
        for (k = 0, queued = 0; k < st.n_alarmed; k++)
            queued = (uint8_t)(queued | (st.alarmed[k] == ch));
        if (!queued)
            st.alarmed[st.n_alarmed++] = ch;
    }
}

void tsc_send(tsc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    hal_send(frame, len);
}

void tsc_on_init(tsc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
}

void tsc_on_status_req(tsc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER;
}

void tsc_on_set_alarm_tsc(tsc_node *node, const arachnae_header *h, const arachnae_set_alarm_tsc_t *msg)
{
    /* limit and data are both whole degrees C (spec): no conversion */
    (void)node;
    (void)h;
    if (msg->channel < PROBES_MAX)
        fw_alarm_set(&st.alarms[msg->channel], msg->limit, FW_ABOVE);
}

/* seed 3.2.11: the skeleton answers with XMIT_DATA_TSC what this fills in (spec reply_to) */
uint8_t tsc_on_xmit_data(tsc_node *node, const arachnae_header *h, arachnae_xmit_data_tsc_t *m)
{
    uint8_t ch, k;
    (void)node;
    (void)h;
    if (!st.probes)
        measure(hal_ms());
    if (!st.probes)
        return 0;                            /* no probe fitted: nothing to send */
    if (st.n_alarmed) {
        ch = st.alarmed[0];
        for (k = 1; k < st.n_alarmed; k++)
            st.alarmed[k - 1] = st.alarmed[k];
        st.n_alarmed--;
    } else {
        ch = st.channel;
        st.channel = (uint8_t)((ch + 1u) % st.probes);
    }
    if (!st.n_alarmed)
        fw_fetched(&st.slave);
    m->channel = ch;
    m->temperature = (int8_t)st.latest[ch];
    return 1;
}

void fw_behaviour_init(void *vnode)
{
    fw_slave_init(&st.slave, ((tsc_node *)vnode)->address);
    st.next_measure = hal_ms();
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    (void)vnode;
    if (fw_every(&st.next_measure, now, TUNING_TSC_MEASURE_MS))
        measure(now);
    fw_slave_poll(&st.slave, now);
}
