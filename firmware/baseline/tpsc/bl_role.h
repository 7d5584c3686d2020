/* Hand-written TPSC protocol constants (baseline; tests/firmware/test_size.py checks them against the spec). */
#ifndef BL_ROLE_H
#define BL_ROLE_H
#define BL_OWN 0x28u
#define BL_RX_MAX 6u              /* it receives empty payloads only */
#define BL_TX_MAX 7u              /* ID_ACK, STATUS_ACK_ORDER, XMIT_DATA_TPSC: 1 payload byte */
#define BL_SPU 0x04u
#define BL_OP_INIT 0x01u
#define BL_OP_ID_REQ 0x02u
#define BL_OP_ID_ACK 0x03u
#define BL_OP_STATUS_REQ 0x04u
#define BL_OP_STATUS_ACK_ORDER 0x06u
#define BL_OP_XMIT_DATA 0x45u
#define BL_OP_DATA_RDY 0x46u
#define BL_OP_XMIT_DATA_TPSC 0x48u
#endif
