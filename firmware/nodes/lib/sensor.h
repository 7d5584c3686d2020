/*
 * What the sensor controllers on the SPU's bus share (seed 3.2.11-3.2.17), the C
 * counterpart of behaviours/sensors.py (_Sensor, AlarmLimit, _RangeSensor) and of
 * the slave side of behaviours/runtime.py (Runtime._slave_start, address_backoff):
 * DATA_RDY announcements, SET_ALARM limits, the three-plus-three rule, means.
 * Times are hal_ms() milliseconds; numbers come from role_config.h (spec and
 * behaviours/tuning.py, firmware/roles.py), never typed in here.
 */
#ifndef FW_SENSOR_H
#define FW_SENSOR_H
#include <stdint.h>

enum { FW_BELOW, FW_ABOVE, FW_BEYOND };

/* One SET_ALARM limit (behaviours.sensors.AlarmLimit): fires once when the value crosses
 * it, re-arms once it is back by `rearm` raw steps. */
typedef struct {
    int16_t limit;
    uint8_t sense;
    uint8_t armed;
    uint8_t set;        /* 0: no limit on this channel */
} fw_alarm;

void fw_alarm_set(fw_alarm *a, int16_t limit, uint8_t sense);
/* 1 on the crossing edge only. */
uint8_t fw_alarm_check(fw_alarm *a, int16_t v, int16_t rearm);

/* Python round(sum / n): half to even (n = 2 can end in .5). */
int16_t fw_mean(const int16_t *v, uint8_t n);

/* seed 3.2.11/3.2.13: three readings averaged per channel; if one channel spreads further
 * than `spread`, three more; if those spread too: 0 (UNRELIABLE), else 1 and out[] the means.
 * A reading is hal_sample(kind, arg): `channels` values, then, if `timed`, the conversion's
 * time in microseconds, added to *time_us (the sonar's echo times). *second_sets counts the
 * second sets taken. (No function pointer: the static stack figure stays exact.) */
uint8_t fw_three_plus_three(uint8_t kind, uint16_t arg, uint8_t channels, uint8_t timed, int16_t spread,
                            int16_t *out, uint16_t *second_sets, uint32_t *time_us);

/* A slave's DATA_RDY to its master (behaviours.sensors._Sensor.announce / fetched, runtime slave_send). */
typedef struct {
    uint8_t own;            /* own address */
    uint8_t pending;        /* a DATA_RDY waits to get through */
    uint8_t waiting_echo;
    uint8_t announced;      /* announced and not fetched yet */
    uint8_t collided;       /* a corrupt frame was seen: the backoff window runs from collision_at */
    uint8_t slot_used;      /* sent in our slot of the open window */
    uint16_t announced_at, collision_at, rx_errors;
    uint16_t pause_at;      /* fw_rx_pause_chars when the window opened */
} fw_slave;

void fw_slave_init(fw_slave *s, uint8_t own);
/* DATA_RDY once until the master fetches the data, again after TUNING_SENSOR_DATA_RDY_RETRY_MS;
 * `force`: whatever was announced. */
void fw_announce(fw_slave *s, uint16_t now, uint8_t force);
void fw_fetched(fw_slave *s);
/* A range sensor's new reliability status (seed 3.2.11/3.2.13): recorded, noted on the debug port and,
 * unless it is free-running, announced to the SPU. Nothing happens if it did not change. */
void fw_declare(fw_slave *s, uint8_t *status, uint8_t new_status, uint8_t free_run, uint16_t now);
/* From the behaviour's poll: sends the pending DATA_RDY when the rules allow, judges its echo. */
void fw_slave_poll(fw_slave *s, uint16_t now);

/* Each channel's limit checked against values[]; returns the mask of channels that fired
 * and, if any did, counts an alarm, notes it and announces (seed 3.2.13-3.2.17). */
uint8_t fw_check_alarms(fw_alarm *alarms, const int16_t *values, uint8_t channels, int16_t rearm, fw_slave *s,
                        uint16_t now);

/* The last three readings (seed 3.2.16, 3.2.17: the value sent is their mean). */
typedef struct {
    int16_t v[3];
    uint8_t n, next;
} fw_last3;
void fw_last3_add(fw_last3 *l, int16_t v);
int16_t fw_last3_mean(const fw_last3 *l);   /* n > 0 */

/* A periodic measurement on the node's own clock (Runtime.every: now, then every period). */
uint8_t fw_every(uint16_t *next, uint16_t now, uint16_t period);

#endif /* FW_SENSOR_H */
