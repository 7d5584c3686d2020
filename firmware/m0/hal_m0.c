/*
 * hal.h for a Cortex-M0 size image: an nRF51-style UART (base 0x40002000) and the
 * SysTick at 1 kHz; the idle gap is timed in whole milliseconds from the tick. GPIO pins: 2 DE and /RE,
 * 3 collision-detect latch, 4 carrier detect, 5 test point, 0..1 the sensor inputs.
 * Built and measured (make size), not run: no M0 simulator is part of the SIL.
 */
#include "role_config.h"
#include "hal.h"

#define REG(addr) (*(volatile uint32_t *)(addr))
#define UART_BASE 0x40002000UL
#define UART_STARTRX REG(UART_BASE + 0x000UL)
#define UART_STARTTX REG(UART_BASE + 0x008UL)
#define UART_RXDRDY REG(UART_BASE + 0x108UL)
#define UART_TXDRDY REG(UART_BASE + 0x11CUL)
#define UART_INTENSET REG(UART_BASE + 0x304UL)
#define UART_ENABLE REG(UART_BASE + 0x500UL)
#define UART_RXD REG(UART_BASE + 0x518UL)
#define UART_TXD REG(UART_BASE + 0x51CUL)
#define UART_BAUDRATE REG(UART_BASE + 0x524UL)
#define GPIO_OUTSET REG(0x50000508UL)
#define GPIO_OUTCLR REG(0x5000050CUL)
#define GPIO_IN REG(0x50000510UL)
#define GPIO_DIRSET REG(0x50000518UL)
#define GPIO_PIN_CNF(n) REG(0x50000700UL + 4UL * (n))   /* 0: input, buffer connected, no pull */
#define PIN_CNF_PULLUP (3UL << 2)
#define SYST_CSR REG(0xE000E010UL)
#define SYST_RVR REG(0xE000E014UL)
#define NVIC_ISER REG(0xE000E100UL)
#define CPU_HZ 16000000UL
#define PIN_DE (1UL << 2)
#define PIN_TP (1UL << 5)
#define PIN_CD (1UL << 3)   /* collision-detect latch */
/* Carrier detect, the same board assumption as the AVR's PC3 (avr/hal_avr.c): the transceiver's RO through a
 * retriggerable monostable of one character, high from a frame's start bit on, before its first byte is in. */
#define PIN_CARRIER (1UL << 4)
#define GAP_MS ((FW_IDLE_GAP_US + 999UL) / 1000UL)

static volatile uint16_t ms, last_rx_ms;
static volatile uint8_t gap_armed;
static volatile uint16_t tx_end_ms;
volatile uint8_t fw_rx_from_master = 1;   /* hal.h; nothing heard yet counts as the master's */
static uint8_t sent;

void hal_init(void)
{
    UART_BAUDRATE = (uint32_t)(FW_BAUD * 268435456ULL / CPU_HZ); /* nRF51: baud * 2^32 / 16 MHz, coarse */
    UART_ENABLE = 4u;
    UART_INTENSET = 1UL << 2;                                    /* RXDRDY */
    UART_STARTRX = 1u;
    UART_STARTTX = 1u;
    GPIO_DIRSET = PIN_DE | PIN_TP;
    GPIO_PIN_CNF(0) = PIN_CNF_PULLUP;                            /* the sensor inputs, active low */
    GPIO_PIN_CNF(1) = PIN_CNF_PULLUP;
    GPIO_PIN_CNF(3) = 0;                                         /* the latch and carrier detect: inputs */
    GPIO_PIN_CNF(4) = 0;
    SYST_RVR = CPU_HZ / 1000UL - 1UL;
    SYST_CSR = 7u;
}

void hal_enable_interrupts(void)
{
    NVIC_ISER = 1UL << 2;                                        /* UART0 IRQ */
    __asm volatile("cpsie i" ::: "memory");
}

void hal_idle(void) { __asm volatile("wfi"); }

uint16_t hal_ms(void) { return ms; }

uint8_t hal_line_idle(void) { return (uint8_t)!gap_armed; }

void SysTick_Handler(void)
{
    ms++;
    if (gap_armed && (uint16_t)(ms - last_rx_ms) >= GAP_MS) {
        gap_armed = 0;
        fw_rx_gap();
    }
}

void UART0_IRQHandler(void)
{
    uint8_t byte;
    UART_RXDRDY = 0;
    byte = (uint8_t)UART_RXD;
    last_rx_ms = ms;
    gap_armed = 1;
    fw_rx_byte(byte);
}

void hal_send(const uint8_t *frame, uint16_t len)
{
    uint16_t i;
    uint16_t t0;
    t0 = ms;
    while ((uint16_t)(ms - t0) < 1u + FW_TURNAROUND_US / 1000u)
        ;
    GPIO_OUTSET = PIN_DE;                                        /* DE and /RE; clears the latch */
    for (i = 0; i < len; i++) {
        UART_TXDRDY = 0;
        UART_TXD = frame[i];
        while (UART_TXDRDY == 0u)
            ;
    }
    GPIO_OUTCLR = PIN_DE;
    fw_rx_from_master = 0;                      /* the line's last frame is ours (hal.h) */
    tx_end_ms = ms;
    sent = 1;
}

uint8_t hal_echo_status(void)
{
    if (!sent || (uint16_t)(ms - tx_end_ms) < FW_CD_WAIT_MS)
        return HAL_ECHO_PENDING;
    return (GPIO_IN & PIN_CD) ? HAL_ECHO_CORRUPT : HAL_ECHO_OK;
}

uint8_t hal_inputs(void) { return (uint8_t)(~GPIO_IN & 0x03u); }

uint16_t hal_line_quiet_ms(void)
{
    uint16_t rx = (uint16_t)(ms - last_rx_ms), tx = (uint16_t)(ms - tx_end_ms);
    if (gap_armed || (GPIO_IN & PIN_CARRIER))       /* a frame is coming in, or just began */
        return 0;
    return sent && tx < rx ? tx : rx;
}

/* Sensor front end on SPI0 (nRF51 registers): request code and argument out, reply in. */
#define SPI_READY REG(0x40003108UL)
#define SPI_RXD REG(0x40003518UL)
#define SPI_TXD REG(0x4000351CUL)
static uint8_t spi_xfer(uint8_t out)
{
    SPI_READY = 0;
    SPI_TXD = out;
    while (SPI_READY == 0u)
        ;
    return (uint8_t)SPI_RXD;
}

static void port_request(uint8_t code, uint16_t arg)
{
    (void)spi_xfer(code);
    (void)spi_xfer((uint8_t)arg);
    (void)spi_xfer((uint8_t)(arg >> 8));
}

void hal_sample(uint8_t kind, uint16_t arg, int16_t *out, uint8_t n)
{
    uint8_t i;
    port_request(kind, arg);
    for (i = 0; i < n; i++) {
        uint8_t lo = spi_xfer(0);
        out[i] = (int16_t)((uint16_t)lo | (uint16_t)((uint16_t)spi_xfer(0) << 8));
    }
}

void hal_note(uint8_t kind, uint16_t arg) { port_request(kind, arg); }

void hal_test_point(uint8_t on)
{
    if (on)
        GPIO_OUTSET = PIN_TP;
    else
        GPIO_OUTCLR = PIN_TP;
}
