/* Hand-written RLC protocol constants (baseline; tests/firmware/test_size.py checks them against the spec). */
#ifndef BL_ROLE_H
#define BL_ROLE_H
#define BL_OWN 0x08u
#define BL_RX_MAX 6u              /* it receives empty payloads only */
#define BL_TX_MAX 7u              /* ID_ACK, STATUS_ACK_BUSY: 1 payload byte */
#define BL_OP_INIT 0x01u
#define BL_OP_ID_REQ 0x02u
#define BL_OP_ID_ACK 0x03u
#define BL_OP_STATUS_REQ 0x04u
#define BL_OP_STATUS_ACK_BUSY 0x05u
#define BL_OP_XMIT_GRANT 0x11u
#endif
