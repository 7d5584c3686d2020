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

/* written by the RX interrupt: read until two reads agree (no torn 16-bit value) */
static uint16_t isr_word(volatile uint16_t *v)
{
    uint16_t e;
    do {
        e = *v;
    } while (e != *v);
    return e;
}

static uint16_t rx_errors(void) { return isr_word(&fw_rx_corrupt); }

void fw_slave_init(fw_slave *s, uint8_t own)
{
    s->own = own;
    s->pending = s->waiting_echo = s->announced = s->collided = s->slot_used = 0;
    s->rx_errors = rx_errors();
}

void fw_declare(fw_slave *s, uint8_t *status, uint8_t new_status, uint8_t free_run, uint16_t now)
{
    if (new_status == *status)
        return;
    *status = new_status;
    fw_debug[FW_DBG_STATUS] = new_status;
    hal_note(HAL_NOTE_STATUS, new_status);
    if (!free_run)
        fw_announce(s, now, 0);     /* CHOICE: a status change is news for the SPU */
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

/* hal_ms() ticks: a span read as n ms lasted more than n - 1 ms and less than n + 1 ms */
#define TICK_US 1000UL

/* Microseconds of the backoff window (runtime._in_window, _backoff_wait) gone since the corrupt frame:
 * idle slots, so the line time of frames other than requests heard since then does not count. */
static uint32_t window_us(const fw_slave *s, uint16_t now)
{
    uint32_t since = (uint32_t)(uint16_t)(now - s->collision_at) * TICK_US;
    uint32_t pause = (uint32_t)(uint16_t)(isr_word(&fw_rx_pause_chars) - s->pause_at) * FW_CHAR_US;
    return since > pause ? since - pause : 0u;
}

/* runtime._in_window: the window after a collision is still open (scope all). */
static uint8_t in_window(fw_slave *s, uint16_t now)
{
    if (!FW_BACKOFF_SCOPE_ALL || !s->collided)
        return 0;
    if (window_us(s, now) >= FW_REQUESTERS * FW_BACKOFF_STEP_US + TICK_US) {
        s->collided = 0;                     /* the window is over */
        return 0;
    }
    return 1;
}

/* runtime._backoff_wait: 1 while this slave must wait for its slot of the window (rank x step), the slot
 * shrunk by the clock's tick at both ends so the request starts inside it whatever the tick's phase. */
static uint8_t backing_off(fw_slave *s, uint16_t now)
{
    uint32_t since, mine = FW_BACKOFF_RANK * FW_BACKOFF_STEP_US;
    if (!in_window(s, now))
        return 0;
    since = window_us(s, now);
    return (uint8_t)(s->slot_used || since < mine + TICK_US || since + 2u * TICK_US >= mine + FW_BACKOFF_STEP_US);
}

/* A corrupt frame ended `at` (hal_ms): the window starts again (runtime._open_window). */
static void open_window(fw_slave *s, uint16_t at)
{
    s->collided = 1;
    s->slot_used = 0;
    s->collision_at = at;
    s->pause_at = isr_word(&fw_rx_pause_chars);
}

void fw_slave_poll(fw_slave *s, uint16_t now)
{
    uint8_t out[ARACHNAE_DATA_RDY_FRAME_MAX];
    uint16_t n = 0;
    uint32_t quiet;
    uint16_t errors = rx_errors();
    if (errors != s->rx_errors) {            /* runtime.on_codec_error: a corrupt frame on the bus */
        s->rx_errors = errors;
        open_window(s, isr_word(&fw_rx_corrupt_ms));
    }
    if (s->waiting_echo) {
        uint8_t e = hal_echo_status();
        if (e == HAL_ECHO_PENDING)
            return;
        s->waiting_echo = 0;
        if (e == HAL_ECHO_OK) {
            s->pending = 0;
        } else {                              /* seed 3.2.2: corrupt echo, send again after our slot */
            fw_rx_from_master = 1;            /* our frame ended corrupt, the echo is FW_CD_WAIT_MS old */
            open_window(s, (uint16_t)(now - FW_CD_WAIT_MS));
        }
    }
    if (!s->pending)
        return;
    /* seed 3.2.2 "when the bus is idle" (runtime._slave_start): quiet for longer than the time for what the
     * line carried last, counted in whole ticks; first the line, then our slot of the window */
    if (in_window(s, now))
        quiet = FW_QUIET_IN_WINDOW_US;
    else if (fw_rx_from_master)
        quiet = FW_QUIET_AFTER_MASTER_US;
    else
        quiet = FW_QUIET_AFTER_OTHER_US;
    if ((uint32_t)hal_line_quiet_ms() * TICK_US < quiet + TICK_US || backing_off(s, now))
        return;
    if (arachnae_data_rdy_build(FW_MASTER_ADDRESS, s->own, out, sizeof out, &n) == ARACHNAE_OK) {
        s->slot_used = in_window(s, now);    /* one request per slot: the next waits for the window's end */
        hal_send(out, n);
        s->waiting_echo = 1;
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
