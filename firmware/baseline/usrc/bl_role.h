/* Hand-written USRC protocol constants (baseline; tests/firmware/test_size.py checks them against the spec). */
#ifndef BL_ROLE_H
#define BL_ROLE_H
#define BL_OWN 0x27u
#define BL_RX_MAX 8u              /* HEAD_SET_ABS/REL: 2 payload bytes */
#define BL_TX_MAX 9u              /* XMIT_DATA_USRC: 3 payload bytes */
#define BL_OP_INIT 0x01u
#define BL_OP_ID_REQ 0x02u
#define BL_OP_ID_ACK 0x03u
#define BL_OP_STATUS_REQ 0x04u
#define BL_OP_STATUS_ACK_RANGE 0x07u
#define BL_OP_HEAD_SET_ABS 0x40u
#define BL_OP_HEAD_SET_REL 0x41u
#define BL_OP_HEAD_STEP 0x42u
#define BL_OP_DO_MEASURE 0x43u
#define BL_OP_XMIT_DATA 0x45u
#define BL_OP_DATA_RDY 0x46u
#define BL_OP_XMIT_DATA_USRC 0x47u
#endif
