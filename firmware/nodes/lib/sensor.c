/* Shared sensor-controller logic (sensor.h); same rules as behaviours/sensors.py and runtime.py. */
#include "role_config.h"
#include "hal.h"
#include "sensor.h"

volatile int16_t fw_debug[FW_DBG_COUNT];

void fw_alarm_set(fw_alarm *a, int16_t limit, uint8_t sense)
{
    a->limit = limit;
    a->sense = sense;
    a->armed = 1;
    a->set = 1;
}

static int16_t magnitude(int16_t v) { return v < 0 ? (int16_t)-v : v; }

static uint8_t beyond(const fw_alarm *a, int16_t v)
{
    if (a->sense == FW_BELOW)
        return v < a->limit;
    if (a->sense == FW_ABOVE)
        return v > a->limit;
    return magnitude(v) > magnitude(a->limit);   /* CHOICE (3.2.14): inclination beyond the limit either way */
}

uint8_t fw_alarm_check(fw_alarm *a, int16_t v, int16_t rearm)
{
    if (!a->set)
        return 0;
    if (a->armed && beyond(a, v)) {
        a->armed = 0;
        return 1;
    }
    if (!a->armed) {
        if (a->sense == FW_BELOW)
            a->armed = (int32_t)v >= (int32_t)a->limit + rearm;
        else if (a->sense == FW_ABOVE)
            a->armed = (int32_t)v <= (int32_t)a->limit - rearm;
        else
            a->armed = (int32_t)magnitude(v) <= (int32_t)magnitude(a->limit) - rearm;
    }
    return 0;
}

int16_t fw_mean(const int16_t *v, uint8_t n)
{
    int32_t sum = 0, q, r;
    uint8_t i;
    for (i = 0; i < n; i++)
        sum += v[i];
    q = sum / n;            /* truncates towards zero */
    r = sum - q * n;
    if (r < 0) {            /* floor division */
        q -= 1;
        r += n;
    }
    if (2 * r > n || (2 * r == n && (q & 1)))
        q += 1;             /* round half to even, as Python's round() */
    return (int16_t)q;
}

#define MAX_CHANNELS 3u

uint8_t fw_three_plus_three(uint8_t kind, uint16_t arg, uint8_t channels, uint8_t timed, int16_t spread,
                            int16_t *out, uint16_t *second_sets, uint32_t *time_us)
{
    int16_t sets[3][MAX_CHANNELS + 1u];
    uint8_t attempt, i, c;
    if (channels > MAX_CHANNELS)
        return 0;
    for (attempt = 0; attempt < 2; attempt++) {
        uint8_t ok = 1;
        for (i = 0; i < 3; i++) {
            hal_sample(kind, arg, sets[i], (uint8_t)(channels + (timed ? 1u : 0u)));
            if (timed)
                *time_us += (uint16_t)sets[i][channels];
        }
        for (c = 0; c < channels; c++) {
            int16_t lo = sets[0][c], hi = sets[0][c], col[3];
            for (i = 0; i < 3; i++) {
                col[i] = sets[i][c];
                if (col[i] < lo)
                    lo = col[i];
                if (col[i] > hi)
                    hi = col[i];
            }
            out[c] = fw_mean(col, 3);
            if ((int32_t)hi - lo > spread)
                ok = 0;
        }
        if (ok)
            return 1;
        if (attempt == 0)
            (*second_sets)++;
    }
    return 0;
}

/* fw_rx_corrupt is written by the RX interrupt: read until two reads agree (no torn 16-bit value) */
static uint16_t rx_errors(void)
{
    uint16_t e;
    do {
        e = fw_rx_corrupt;
    } while (e != fw_rx_corrupt);
    return e;
}

void fw_slave_init(fw_slave *s, uint8_t own)
{
    s->own = own;
    s->pending = s->waiting_echo = s->announced = s->collided = 0;
    s->rx_errors = rx_errors();
}

void fw_announce(fw_slave *s, uint16_t now, uint8_t force)
{
    if (!force && s->announced && (uint16_t)(now - s->announced_at) < TUNING_SENSOR_DATA_RDY_RETRY_MS)
        return;
    s->announced = 1;
    s->announced_at = now;
    s->pending = 1;
}

void fw_fetched(fw_slave *s) { s->announced = 0; }

#define US_TO_MS_UP(us) ((uint16_t)(((us) + 999UL) / 1000UL))

/* runtime._backoff_wait: 1 while this slave must wait for its slot of the window after a collision */
static uint8_t backing_off(fw_slave *s, uint16_t now)
{
    uint16_t since, mine, step;
    if (!FW_BACKOFF_SCOPE_ALL || !s->collided)
        return 0;
    step = US_TO_MS_UP(FW_BACKOFF_STEP_US);
    since = (uint16_t)(now - s->collision_at);
    mine = (uint16_t)(FW_BACKOFF_RANK * step);
    if (since >= (uint16_t)(FW_REQUESTERS * step)) {
        s->collided = 0;                     /* the window is over */
        return 0;
    }
    return (uint8_t)(since < mine || since >= (uint16_t)(mine + step));
}

void fw_slave_poll(fw_slave *s, uint16_t now)
{
    uint16_t errors = rx_errors();
    if (errors != s->rx_errors) {            /* runtime.on_codec_error: a corrupt frame on the bus */
        s->rx_errors = errors;
        s->collided = 1;
        s->collision_at = now;
    }
    if (s->waiting_echo) {
        uint8_t e = hal_echo_status();
        if (e == HAL_ECHO_PENDING)
            return;
        s->waiting_echo = 0;
        if (e == HAL_ECHO_OK) {
            s->pending = 0;
        } else {                              /* seed 3.2.2: corrupt echo, send again after our slot */
            s->collided = 1;
            s->collision_at = now;
        }
    }
    if (!s->pending || backing_off(s, now))
        return;
    /* seed 3.2.2 "when the bus is idle": quiet for longer than FW_SLAVE_QUIET_US (AfterReplies) */
    if ((uint32_t)hal_line_quiet_ms() * 1000UL > FW_SLAVE_QUIET_US) {
        uint8_t out[ARACHNAE_DATA_RDY_FRAME_MAX];
        uint16_t n = 0;
        if (arachnae_data_rdy_build(FW_MASTER_ADDRESS, s->own, out, sizeof out, &n) == ARACHNAE_OK) {
            hal_send(out, n);
            s->waiting_echo = 1;
        }
    }
}

uint8_t fw_check_alarms(fw_alarm *alarms, const int16_t *values, uint8_t channels, int16_t rearm, fw_slave *s,
                        uint16_t now)
{
    uint8_t fired = 0, c;
    for (c = 0; c < channels; c++)
        if (fw_alarm_check(&alarms[c], values[c], rearm))
            fired = (uint8_t)(fired | (1u << c));
    if (fired) {
        fw_debug[FW_DBG_ALARMS]++;
        hal_note(HAL_NOTE_ALARM, fired);
        fw_announce(s, now, 0);
    }
    return fired;
}

uint8_t fw_every(uint16_t *next, uint16_t now, uint16_t period)
{
    if ((int16_t)(now - *next) < 0)
        return 0;
    *next = (uint16_t)(now + period);
    return 1;
}

void fw_last3_add(fw_last3 *l, int16_t v)
{
    l->v[l->next] = v;
    l->next = (uint8_t)((l->next + 1u) % 3u);
    if (l->n < 3u)
        l->n++;
}

int16_t fw_last3_mean(const fw_last3 *l) { return fw_mean(l->v, l->n); }
