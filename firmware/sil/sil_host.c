/*
 * sil_host: runs an AVR firmware ELF in simavr, in steps of simulated time that
 * the caller (firmware/sil_bridge.py) chooses, and connects USART0 and a few
 * pins to stdin/stdout as timestamped lines. Time is the AVR's cycle counter.
 *
 *   sil_host [-m MCU] [-f HZ] [-w PIN]... FIRMWARE.elf      PIN like D2 (port D, bit 2)
 *
 * Commands (stdin, one a line)             Answers (stdout)
 *   r CYCLE     run until CYCLE, stopping    t CYCLE HH   the AVR wrote byte HH to UDR0
 *               right after a UART byte      p CYCLE PIN V a watched output pin changed
 *               or a watched pin change      c CYCLE      end of every answer: the cycle now
 *   i CYCLE HH  byte HH arrives at the UART's input at CYCLE (now if CYCLE is past);
 *               simavr raises RXC one character time after that (its own baud timing)
 *   s PIN V     drive input pin PIN to V (0 or 1)
 *   m           m MIN_SP RAMEND: lowest stack pointer seen so far
 *   v HH...     bytes the firmware reads next from its sensor port (GPIOR0), in order
 *   d ADDR N    d HH...      N bytes of data memory from ADDR (the firmware's debug record)
 *   q           quit
 * Sensor port (avr/hal_avr.c): the firmware writes an argument to GPIOR1 (low) and
 * GPIOR2 (high), then a request code to GPIOR0; the host answers
 *   a CYCLE CODE ARG   and stops right after that write, so the caller can load the
 * reply with `v` before the firmware reads it from GPIOR0 (a sensor front end that
 * converts at once; an empty port reads 0).
 * If the AVR crashes or stops: "x CYCLE STATE", exit status 1. Everything simavr
 * itself prints goes to stderr, so stdout carries only the protocol.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "avr_extint.h"
#include "avr_ioport.h"
#include "avr_uart.h"
#include "sim_avr.h"
#include "sim_elf.h"
#include "sim_irq.h"

#define MAX_WATCH 8
#define MAX_INPUT 4096

static avr_t *avr;
static FILE *proto;
static int stop_now;
static uint16_t min_sp = 0xFFFF;

static struct { avr_cycle_count_t at; uint8_t byte; } inq[MAX_INPUT];
static unsigned in_head, in_tail;

static struct { char port; int bit; } watch[MAX_WATCH];

/* data-space addresses of GPIOR0..2 on the ATmega328P: the SIL sensor port */
#define PORT_CODE 0x3E
#define PORT_ARG_LO 0x4A
#define PORT_ARG_HI 0x4B
#define MAX_REPLY 64
static uint8_t reply[MAX_REPLY];
static unsigned reply_head, reply_len;

static void on_port_write(avr_t *a, avr_io_addr_t addr, uint8_t v, void *param)
{
    (void)param;
    a->data[addr] = v;
    reply_head = reply_len = 0;
    fprintf(proto, "a %llu %u %u\n", (unsigned long long)a->cycle, v,
            (unsigned)(a->data[PORT_ARG_LO] | (a->data[PORT_ARG_HI] << 8)));
    stop_now = 1;
}

static uint8_t on_port_read(avr_t *a, avr_io_addr_t addr, void *param)
{
    (void)a;
    (void)addr;
    (void)param;
    return reply_head < reply_len ? reply[reply_head++] : 0u;
}
static int nwatch;

static void no_sleep(avr_t *a, avr_cycle_count_t how_long)
{
    (void)a;
    (void)how_long;     /* simulated time only: never wait in real time */
}

static void on_uart_out(struct avr_irq_t *irq, uint32_t value, void *param)
{
    (void)irq;
    (void)param;
    fprintf(proto, "t %llu %02x\n", (unsigned long long)avr->cycle, value & 0xFFu);
    stop_now = 1;
}

static void on_pin(struct avr_irq_t *irq, uint32_t value, void *param)
{
    int w = (int)(intptr_t)param;
    (void)irq;
    fprintf(proto, "p %llu %c%d %u\n", (unsigned long long)avr->cycle, watch[w].port, watch[w].bit, value ? 1u : 0u);
    stop_now = 1;
}

static avr_cycle_count_t input_due(avr_t *a, avr_cycle_count_t when, void *param)
{
    (void)param;
    (void)when;
    while (in_head != in_tail && inq[in_head % MAX_INPUT].at <= a->cycle) {
        avr_raise_irq(avr_io_getirq(a, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT), inq[in_head % MAX_INPUT].byte);
        in_head++;
    }
    return in_head != in_tail ? inq[in_head % MAX_INPUT].at : 0;
}

static avr_cycle_count_t wake(avr_t *a, avr_cycle_count_t when, void *param)
{
    (void)a;
    (void)when;
    (void)param;
    return 0;     /* only ends a sleep at the requested cycle */
}

static int parse_pin(const char *s, char *port, int *bit)
{
    if (strlen(s) != 2 || s[0] < 'A' || s[0] > 'H' || s[1] < '0' || s[1] > '7')
        return -1;
    *port = s[0];
    *bit = s[1] - '0';
    return 0;
}

static void step(void)
{
    int state = avr_run(avr);
    uint16_t sp = (uint16_t)(avr->data[R_SPL] | (avr->data[R_SPH] << 8));
    if (sp < min_sp && sp != 0)
        min_sp = sp;
    if (state == cpu_Done || state == cpu_Crashed) {
        fprintf(proto, "x %llu %d\n", (unsigned long long)avr->cycle, state);
        fflush(proto);
        exit(1);
    }
}

int main(int argc, char **argv)
{
    const char *mcu = "atmega328p";
    uint32_t freq = 16000000u;
    elf_firmware_t fw;
    char line[256];
    uint32_t flags = 0;
    int opt, fd;

    while ((opt = getopt(argc, argv, "m:f:w:")) != -1) {
        if (opt == 'm')
            mcu = optarg;
        else if (opt == 'f')
            freq = (uint32_t)strtoul(optarg, NULL, 10);
        else if (opt == 'w' && nwatch < MAX_WATCH && parse_pin(optarg, &watch[nwatch].port, &watch[nwatch].bit) == 0)
            nwatch++;
        else {
            fprintf(stderr, "usage: sil_host [-m MCU] [-f HZ] [-w PIN]... FIRMWARE.elf\n");
            return 2;
        }
    }
    if (optind != argc - 1) {
        fprintf(stderr, "usage: sil_host [-m MCU] [-f HZ] [-w PIN]... FIRMWARE.elf\n");
        return 2;
    }
    /* the protocol keeps the original stdout; simavr's own messages go to stderr */
    fd = dup(1);
    if (fd < 0 || dup2(2, 1) < 0 || (proto = fdopen(fd, "w")) == NULL) {
        perror("sil_host");
        return 2;
    }
    memset(&fw, 0, sizeof fw);
    if (elf_read_firmware(argv[optind], &fw) != 0) {
        fprintf(stderr, "sil_host: %s: cannot read the ELF file\n", argv[optind]);
        return 2;
    }
    snprintf(fw.mmcu, sizeof fw.mmcu, "%s", mcu);
    fw.frequency = freq;
    avr = avr_make_mcu_by_name(fw.mmcu);
    if (avr == NULL) {
        fprintf(stderr, "sil_host: unknown MCU %s\n", mcu);
        return 2;
    }
    avr_init(avr);
    avr_load_firmware(avr, &fw);
    avr->sleep = no_sleep;
    /* INT0/INT1 are off, but simavr polls a low level on their pins (PD2 is DE, low
       while listening) every cycle; that would make each sleeping cycle a step */
    avr_extint_set_strict_lvl_trig(avr, 0, 0);
    avr_extint_set_strict_lvl_trig(avr, 1, 0);
    avr_register_io_write(avr, PORT_CODE, on_port_write, NULL);
    avr_register_io_read(avr, PORT_CODE, on_port_read, NULL);
    avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);   /* no console echo, no polling usleep */
    avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT), on_uart_out, NULL);
    for (opt = 0; opt < nwatch; opt++)
        avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(watch[opt].port), watch[opt].bit),
                                on_pin, (void *)(intptr_t)opt);

    while (fgets(line, sizeof line, stdin) != NULL) {
        unsigned long long c;
        unsigned v;
        char pin[8];
        if (line[0] == 'q')
            break;
        if (sscanf(line, "r %llu", &c) == 1) {
            if (c > avr->cycle)
                avr_cycle_timer_register(avr, c - avr->cycle, wake, NULL);
            stop_now = 0;
            while (avr->cycle < c && !stop_now)
                step();
            avr_cycle_timer_cancel(avr, wake, NULL);
        } else if (sscanf(line, "i %llu %x", &c, &v) == 2) {
            if (in_tail - in_head >= MAX_INPUT) {
                fprintf(stderr, "sil_host: input queue full\n");
                return 1;
            }
            inq[in_tail % MAX_INPUT].at = c;
            inq[in_tail % MAX_INPUT].byte = (uint8_t)v;
            in_tail++;
            avr_cycle_timer_cancel(avr, input_due, NULL);
            if (inq[in_head % MAX_INPUT].at <= avr->cycle)
                (void)input_due(avr, avr->cycle, NULL);
            if (in_head != in_tail)
                avr_cycle_timer_register(avr, inq[in_head % MAX_INPUT].at - avr->cycle, input_due, NULL);
        } else if (sscanf(line, "s %7s %u", pin, &v) == 2) {
            char port;
            int bit;
            if (parse_pin(pin, &port, &bit) != 0) {
                fprintf(stderr, "sil_host: bad pin %s\n", pin);
                return 1;
            }
            avr_raise_irq(avr_io_getirq(avr, AVR_IOCTL_IOPORT_GETIRQ(port), bit), v ? 1u : 0u);
        } else if (line[0] == 'v') {
            char *p = line + 1, *end;
            reply_head = reply_len = 0;
            for (;;) {
                unsigned long b = strtoul(p, &end, 16);
                if (end == p)
                    break;
                if (reply_len >= MAX_REPLY || b > 0xFFu) {
                    fprintf(stderr, "sil_host: bad sensor reply: %s", line);
                    return 1;
                }
                reply[reply_len++] = (uint8_t)b;
                p = end;
            }
        } else if (sscanf(line, "d %llu %u", &c, &v) == 2) {
            unsigned k;
            if (c + v > (unsigned long long)avr->ramend + 1u) {
                fprintf(stderr, "sil_host: bad memory range: %s", line);
                return 1;
            }
            fputc('d', proto);
            for (k = 0; k < v; k++)
                fprintf(proto, " %02x", avr->data[c + k]);
            fputc('\n', proto);
        } else if (line[0] == 'm') {
            fprintf(proto, "m %u %u\n", min_sp, avr->ramend);
        } else {
            fprintf(stderr, "sil_host: bad command: %s", line);
            return 1;
        }
        fprintf(proto, "c %llu\n", (unsigned long long)avr->cycle);
        fflush(proto);
    }
    return 0;
}
