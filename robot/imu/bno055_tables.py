"""Bosch BNO055 facts the driver needs, as data (datasheet BST-BNO055-DS000, rev 1.4).

The register map itself lives in the adafruit-circuitpython-bno055 library the driver uses;
these are the values the driver checks or reports.
"""

from __future__ import annotations

#: CHIP_ID register value (section 4.3.1, register 0x00 on page 0).
CHIP_ID = 0xA0
#: UART interface (section 4.7): 115200 baud, 8 data bits, no parity, 1 stop bit.
UART_BAUD = 115200
#: Time the library waits for one reply, times its tries (adafruit_bno055.BNO055_UART:
#: 3 tries x 100 ms per register read, 250 ms per write) [s]: the longest a read can block.
READ_GIVE_UP_S = 0.3
#: Status byte of a 0xEE response (section 4.7, "response status" of the read and write
#: commands; 0x01 is a successful write).
UART_STATUS = {
    0x01: "WRITE_SUCCESS",
    0x02: "READ_FAIL",
    0x03: "WRITE_FAIL",
    0x04: "REGMAP_INVALID_ADDRESS",
    0x05: "REGMAP_WRITE_DISABLED",
    0x06: "WRONG_START_BYTE",
    0x07: "BUS_OVER_RUN_ERROR",
    0x08: "MAX_LENGTH_ERROR",
    0x09: "MIN_LENGTH_ERROR",
    0x0A: "RECEIVE_CHARACTER_TIMEOUT",
}
#: What to do about a status (the application note BST-BNO055-AN012 on UART errors:
#: BUS_OVER_RUN means the chip's MCU was busy with fusion and clears by itself).
UART_STATUS_FIX = {
    0x07: "the chip was busy (it clears within ~0.5 s); read less often",
    0x06: "the line is garbled: check the baud (115200), ground and TX/RX wiring",
    0x0A: "the line is garbled: check the baud (115200), ground and TX/RX wiring",
}
