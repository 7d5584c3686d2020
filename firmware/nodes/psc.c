/*
 * PSC behaviour (seed 3.2.17): battery voltage on its own clock, the mean of the last three
 * readings sent; SET_ALARM: under-voltage below the limit is reported with DATA_RDY. The
 * battery is low when it stays low: the alarm judges the highest mean of the last
 * PSC_ALARM_WINDOW_S (a load dip is shorter, issue 18). Same logic as behaviours/sensors.py PSC.
 */
#include "role_config.h"
#include "hal.h"
#include "lib/sensor.h"

/* behaviours.sensors.PSC: max(1, round(window / period)) means */
#define WINDOW (TUNING_PSC_ALARM_WINDOW_MS / TUNING_PSC_MEASURE_MS > 1u ? \
                (TUNING_PSC_ALARM_WINDOW_MS + TUNING_PSC_MEASURE_MS / 2u) / TUNING_PSC_MEASURE_MS : 1u)

typedef struct {
    fw_slave slave;
    fw_alarm alarm;
    fw_last3 last3;
    int16_t means[WINDOW];
    uint8_t n_means, next_mean, measured;
    uint16_t next_measure;
} psc_state;

static psc_state st;

static int16_t reading(void)
{
    int16_t v;
    hal_sample(HAL_SAMPLE_BATTERY, 0, &v, 1);
    return v;
}

static void measure(uint16_t now)
{
    int16_t mean, level;
    uint8_t i;
    fw_last3_add(&st.last3, reading());
    mean = fw_last3_mean(&st.last3);
    st.means[st.next_mean] = mean;
    st.next_mean = (uint8_t)((st.next_mean + 1u) % WINDOW);
    if (st.n_means < WINDOW)
        st.n_means++;
    level = st.means[0];
    for (i = 1; i < st.n_means; i++)
        if (st.means[i] > level)
            level = st.means[i];
    /* debug port: the mean reported now, the lowest mean and the lowest level judged */
    if (!st.measured || mean < fw_debug[FW_DBG_MEAN_MIN])
        fw_debug[FW_DBG_MEAN_MIN] = mean;
    if (!st.measured || level < fw_debug[FW_DBG_LEVEL_MIN])
        fw_debug[FW_DBG_LEVEL_MIN] = level;
    fw_debug[FW_DBG_MEAN] = mean;
    st.measured = 1;
    (void)fw_check_alarms(&st.alarm, &level, 1, TUNING_ALARM_REARM_RAW, &st.slave, now);
}

void psc_send(psc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    hal_send(frame, len);
}

void psc_on_init(psc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
}

void psc_on_status_req(psc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER;
}

void psc_on_set_alarm_psc(psc_node *node, const arachnae_header *h, const arachnae_set_alarm_psc_t *msg)
{
    /* the limit through physical units into the data field's steps (behaviours.sensors.limit_in) */
    uint8_t raw = 0;
    (void)node;
    (void)h;
#if FW_ALARM_LIMIT_IS_DATA_RAW
    raw = msg->limit;                        /* one encoding for both (spec; checked by roles.py) */
#else
    if (arachnae_xmit_data_psc_voltage_from_milli(arachnae_set_alarm_psc_limit_to_milli(msg->limit), &raw)
        != ARACHNAE_OK)
        raw = 0;                             /* below the measuring range: never crossed */
#endif
    fw_alarm_set(&st.alarm, (int16_t)raw, FW_BELOW);
}

/* seed 3.2.11: the skeleton answers with XMIT_DATA_PSC what this fills in (spec reply_to) */
uint8_t psc_on_xmit_data(psc_node *node, const arachnae_header *h, arachnae_xmit_data_psc_t *m)
{
    (void)h;
    (void)node;
    fw_fetched(&st.slave);
    m->voltage = (uint8_t)(st.last3.n ? fw_last3_mean(&st.last3) : reading());
    return 1;
}

void fw_behaviour_init(void *vnode)
{
    fw_slave_init(&st.slave, ((psc_node *)vnode)->address);
    st.next_measure = hal_ms();
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    (void)vnode;
    if (fw_every(&st.next_measure, now, TUNING_PSC_MEASURE_MS))
        measure(now);
    fw_slave_poll(&st.slave, now);
}
