/* Minimal Cortex-M0 start-up for the size image: vector table, .data copy, .bss clear. */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void Reset_Handler(void);
void Default_Handler(void);
void SysTick_Handler(void);
void UART0_IRQHandler(void);

void Default_Handler(void)
{
    for (;;)
        ;
}

void Reset_Handler(void)
{
    uint32_t *src = &_sidata, *dst = &_sdata;
    while (dst < &_edata)
        *dst++ = *src++;
    for (dst = &_sbss; dst < &_ebss;)
        *dst++ = 0;
    (void)main();
    for (;;)
        ;
}

typedef void (*vector_fn)(void);

/* 16 core vectors, then device IRQs 0..2 (IRQ 2: UART0 on an nRF51). */
__attribute__((section(".isr_vector"), used)) static const vector_fn vectors[16 + 3] = {
    (vector_fn)(uintptr_t)&_estack, Reset_Handler, Default_Handler, Default_Handler,
    0, 0, 0, 0, 0, 0, 0, Default_Handler, 0, 0, Default_Handler, SysTick_Handler,
    Default_Handler, Default_Handler, UART0_IRQHandler,
};
