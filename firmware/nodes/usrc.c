/*
 * USRC behaviour (seed 3.2.11): the sonar head turns in 1 degree steps; each measurement
 * takes three pings, three more if they spread too far, and declares the sensor UNRELIABLE
 * if those spread too. FREE_RUN scans on and on and announces each sector's nearest echo
 * with DATA_RDY; DO_MEASURE measures at the head's angle; HEAD_SET_ABS / HEAD_SET_REL /
 * HEAD_STEP turn the head. Same logic as behaviours/sensors.py USRC.
 */
#include "role_config.h"
#include "hal.h"
#include "lib/sensor.h"

#define HEAD_DEGREES 360u   /* seed 3.2.11: the head turns all round, 1 degree a step (angle 0..359) */

typedef struct {
    uint8_t distance;
    uint16_t angle;
} echo_t;

typedef struct {
    fw_slave slave;
    uint8_t status, free_run, scanning, has_sector, has_ready;
    uint16_t head;
    echo_t latest, sector, ready;
    uint32_t tof_us;                /* echo times of the pings of the last measurement */
    uint16_t next_step, second_sets;
} usrc_state;

static usrc_state st;

static void declare(uint8_t status, uint16_t now)
{
    fw_declare(&st.slave, &st.status, status, st.free_run, now);
}

static void measure(uint16_t now)
{
    int16_t got;
    uint8_t ok;
    st.tof_us = 0;
    fw_debug[FW_DBG_MEASUREMENTS]++;
    /* each ping: the distance and its echo time (us), at the head's angle */
    ok = fw_three_plus_three(HAL_SAMPLE_SONAR, st.head, 1, 1, TUNING_USRC_SPREAD_RAW, &got, &st.second_sets,
                             &st.tof_us);
    fw_debug[FW_DBG_SECOND_SETS] = (int16_t)st.second_sets;
    if (!ok) {
        declare(ARACHNAE_RANGE_STATUS_UNRELIABLE, now);
        return;
    }
    st.latest.distance = (uint8_t)got;
    st.latest.angle = st.head;
}

static void scan_step(uint16_t now)
{
    measure(now);
    if (st.status == ARACHNAE_RANGE_STATUS_IN_ORDER && st.latest.angle == st.head) {
        if (!st.has_sector || st.latest.distance < st.sector.distance) {
            st.sector = st.latest;
            st.has_sector = 1;
        }
    }
    st.head = (uint16_t)((st.head + 1u) % HEAD_DEGREES);
    if (st.head % TUNING_USRC_SECTOR_DEG == 0u && st.has_sector) {
        /* FREE_RUN (spec): announce data with DATA_RDY; not while the sensor does not trust itself (6.2) */
        st.ready = st.sector;
        st.has_ready = 1;
        st.has_sector = 0;
        if (st.status == ARACHNAE_RANGE_STATUS_IN_ORDER) {
            fw_fetched(&st.slave);
            fw_announce(&st.slave, now, 0);
        }
    }
    st.next_step = (uint16_t)(now + (st.tof_us + 999UL) / 1000UL + TUNING_USRC_HEAD_STEP_MS);
}

void usrc_send(usrc_node *node, const uint8_t *frame, uint16_t len)
{
    (void)node;
    hal_send(frame, len);
}

void usrc_on_init(usrc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
    st.status = ARACHNAE_RANGE_STATUS_IN_ORDER;   /* CHOICE: initialised again, the sensor trusts itself */
    fw_debug[FW_DBG_STATUS] = st.status;
}

void usrc_on_status_req(usrc_node *node, const arachnae_header *h, arachnae_status_ack_range_t *reply)
{
    (void)node;
    (void)h;
    reply->status = st.status;
}

void usrc_on_head_set_abs(usrc_node *node, const arachnae_header *h, const arachnae_head_set_abs_t *msg)
{
    (void)node;
    (void)h;
    st.head = (uint16_t)(msg->angle % HEAD_DEGREES);
}

void usrc_on_head_set_rel(usrc_node *node, const arachnae_header *h, const arachnae_head_set_rel_t *msg)
{
    int16_t a = (int16_t)((int16_t)st.head + msg->angle) % (int16_t)HEAD_DEGREES;
    (void)node;
    (void)h;
    st.head = (uint16_t)(a < 0 ? a + (int16_t)HEAD_DEGREES : a);    /* Python %: never negative */
}

void usrc_on_head_step(usrc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
    st.head = (uint16_t)((st.head + 1u) % HEAD_DEGREES);
}

void usrc_on_do_measure(usrc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
    measure(hal_ms());
}

void usrc_on_free_run(usrc_node *node, const arachnae_header *h)
{
    (void)node;
    (void)h;
    st.free_run = 1;
    if (!st.scanning) {
        st.scanning = 1;
        st.next_step = (uint16_t)(hal_ms() + TUNING_USRC_HEAD_STEP_MS);
    }
}

/* seed 3.2.11: the skeleton answers with XMIT_DATA_USRC what this fills in (spec reply_to) */
uint8_t usrc_on_xmit_data(usrc_node *node, const arachnae_header *h, arachnae_xmit_data_usrc_t *m)
{
    /* the last sector's nearest echo once announced, else the last measured distance (3.2.11) */
    echo_t e = st.has_ready ? st.ready : st.latest;
    (void)node;
    (void)h;
    st.has_ready = 0;
    fw_fetched(&st.slave);
    m->distance = e.distance;
    m->angle = e.angle;
    return 1;
}

void fw_behaviour_init(void *vnode)
{
    fw_slave_init(&st.slave, ((usrc_node *)vnode)->address);
    st.status = ARACHNAE_RANGE_STATUS_IN_ORDER;
    st.latest.distance = UINT8_MAX;          /* nothing seen yet: the top of the range */
}

void fw_behaviour_poll(void *vnode, uint16_t now)
{
    (void)vnode;
    if (st.scanning && (int16_t)(now - st.next_step) >= 0)
        scan_step(now);
    fw_slave_poll(&st.slave, now);
}
