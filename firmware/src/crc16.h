/* CRC-16/CCITT-FALSE, the frame check of the rig protocol (see protocol.h). */
#ifndef RIG_CRC16_H
#define RIG_CRC16_H

#include <stddef.h>
#include <stdint.h>

uint16_t crc16_update(uint16_t crc, uint8_t byte);
uint16_t crc16(const uint8_t *data, size_t length);

#endif
