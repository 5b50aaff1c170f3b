/*
 * The emulated board's serial port: a pseudo-terminal whose master side the emulation reads and
 * writes without ever blocking, from its own thread, so a host that stops reading or goes away
 * cannot stall the board (bytes it does not take are dropped, as by a USB-serial bridge).
 */
#ifndef RIG_PTY_LINK_H
#define RIG_PTY_LINK_H

#include <stddef.h>
#include <stdint.h>

#define PTY_LINK_OUT_CAPACITY 16384

typedef struct {
	int master;
	char path[128];
	uint8_t out[PTY_LINK_OUT_CAPACITY];
	size_t out_start;
	size_t out_length;
	unsigned long dropped;
} pty_link_t;

/* Opens a new pseudo-terminal in raw mode; its slave path is in link->path. Returns 0, or -1
 * with errno set. */
int pty_link_open(pty_link_t *link);

/* Closes the master side: a host holding the slave sees the line hang up. */
void pty_link_close(pty_link_t *link);

/* Queues a byte for the host, or drops and counts it when the queue is full. */
void pty_link_send(pty_link_t *link, uint8_t byte);

/* Writes as much of the queue as the pseudo-terminal takes now. */
void pty_link_flush(pty_link_t *link);

/* Reads up to `capacity` bytes the host has written; returns how many (0 when none). */
size_t pty_link_receive(pty_link_t *link, uint8_t *bytes, size_t capacity);

#endif
