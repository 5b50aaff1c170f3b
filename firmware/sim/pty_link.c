#define _GNU_SOURCE
#include "pty_link.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

int pty_link_open(pty_link_t *link)
{
	link->out_start = 0;
	link->out_length = 0;
	link->master = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
	if (link->master < 0)
		return -1;
	struct termios settings;
	if (grantpt(link->master) != 0 || unlockpt(link->master) != 0 ||
	    ptsname_r(link->master, link->path, sizeof link->path) != 0 ||
	    tcgetattr(link->master, &settings) != 0) {
		int error = errno;
		close(link->master);
		link->master = -1;
		errno = error;
		return -1;
	}
	cfmakeraw(&settings);
	tcsetattr(link->master, TCSANOW, &settings);
	return 0;
}

void pty_link_close(pty_link_t *link)
{
	if (link->master >= 0)
		close(link->master);
	link->master = -1;
	link->out_length = 0;
}

void pty_link_send(pty_link_t *link, uint8_t byte)
{
	if (link->out_length == PTY_LINK_OUT_CAPACITY) {
		link->dropped++;
		return;
	}
	link->out[(link->out_start + link->out_length) % PTY_LINK_OUT_CAPACITY] = byte;
	link->out_length++;
}

void pty_link_flush(pty_link_t *link)
{
	while (link->out_length && link->master >= 0) {
		size_t run = PTY_LINK_OUT_CAPACITY - link->out_start;
		if (run > link->out_length)
			run = link->out_length;
		ssize_t written = write(link->master, link->out + link->out_start, run);
		if (written <= 0)
			return; /* EAGAIN: the host's buffer is full; EIO: no host has the port open */
		link->out_start = (link->out_start + (size_t)written) % PTY_LINK_OUT_CAPACITY;
		link->out_length -= (size_t)written;
	}
}

size_t pty_link_receive(pty_link_t *link, uint8_t *bytes, size_t capacity)
{
	if (link->master < 0 || capacity == 0)
		return 0;
	ssize_t got = read(link->master, bytes, capacity);
	return got > 0 ? (size_t)got : 0; /* EAGAIN: nothing written; EIO: no host has it open */
}
