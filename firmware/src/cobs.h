/* Consistent Overhead Byte Stuffing: removes every zero byte so that 0x00 can end a frame. */
#ifndef RIG_COBS_H
#define RIG_COBS_H

#include <stddef.h>
#include <stdint.h>

/* The most bytes cobs_encode writes for `length` input bytes. */
#define COBS_MAX_ENCODED(length) ((length) + (length) / 254 + 1)

/* Encodes `length` bytes into `out` (COBS_MAX_ENCODED(length) bytes long, no delimiter added);
 * returns the encoded length. */
size_t cobs_encode(const uint8_t *data, size_t length, uint8_t *out);

/* Decodes `length` bytes (without the delimiter) into `out`, which holds `capacity` bytes.
 * Returns the decoded length, or -1 when the input holds a zero, ends inside a block, or does
 * not fit. */
int cobs_decode(const uint8_t *data, size_t length, uint8_t *out, size_t capacity);

#endif
