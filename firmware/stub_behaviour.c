/* Behaviour hooks of a role without hand-written behaviour (size images only). */
#include "hal.h"

void fw_behaviour_init(void *node) { (void)node; }
void fw_behaviour_poll(void *node, uint16_t now_ms) { (void)node; (void)now_ms; }
