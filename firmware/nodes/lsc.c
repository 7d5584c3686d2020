/*
 * LSC behaviour (seed 3.2.16): "misst laufend die Umgebungshelligkeit" on its own clock and
 * sends the mean of the last three readings; SET_ALARM: brighter than the limit is reported
 * with DATA_RDY. Same logic as behaviours/sensors.py LSC (_Averaging).
 */
#include "role_config.h"
#include "hal.h"
#include "lib/sensor.h"

typedef struct {
    fw_slave slave;
    fw_alarm alarm;
    fw_last3 last3;
    uint16_t next_measure;
} lsc_state;

static lsc_state st;

static int16_t reading(void)
{
    int16_t v;
    hal_sample(HAL_SAMPLE_LIGHT, 0, &v, 1);
    return v;
}

void lsc_send(lsc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    hal_send(frame, len);
}

void lsc_on_init(lsc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
}

void lsc_on_status_req(lsc_node *node, const arachnae_header *h, arachnae_status_ack_order_t *reply)
{
    (void)node;
    (void)h;
    reply->status = ARACHNAE_ORDER_STATUS_IN_ORDER;
}

void lsc_on_set_alarm_lsc(lsc_node *node, const arachnae_header *h, const arachnae_set_alarm_lsc_t *msg)
{
    /* the limit through physical units into the data field's steps (behaviours.sensors.limit_in) */
    uint8_t raw = 0;
    (void)node;
    (void)h;
#if FW_ALARM_LIMIT_IS_DATA_RAW
    raw = msg->limit;                        /* one encoding for both (spec; checked by roles.py) */
#else
    if (arachnae_xmit_data_lsc_brightness_from_milli(arachnae_set_alarm_lsc_limit_to_milli(msg->limit), &raw)
        != ARACHNAE_OK)
        raw = UINT8_MAX;
#endif
    fw_alarm_set(&st.alarm, (int16_t)raw, FW_ABOVE);
}

/* seed 3.2.11: the skeleton answers with XMIT_DATA_LSC what this fills in (spec reply_to) */
uint8_t lsc_on_xmit_data(lsc_node *node, const arachnae_header *h, arachnae_xmit_data_lsc_t *m)
{
    (void)h;
    (void)node;
    fw_fetched(&st.slave);
    m->brightness = (uint8_t)(st.last3.n ? fw_last3_mean(&st.last3) : reading());
    return 1;
}

void fw_behaviour_init(void *vnode)
{
    fw_slave_init(&st.slave, ((lsc_node *)vnode)->address);
    st.next_measure = hal_ms();
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    (void)vnode;
    if (fw_every(&st.next_measure, now, TUNING_LSC_MEASURE_MS)) {
        int16_t mean;
        fw_last3_add(&st.last3, reading());
        mean = fw_last3_mean(&st.last3);
        (void)fw_check_alarms(&st.alarm, &mean, 1, TUNING_ALARM_REARM_RAW, &st.slave, now);
    }
    fw_slave_poll(&st.slave, now);
}
