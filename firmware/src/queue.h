/*
 * Single-producer single-consumer ring queues between an interrupt handler and the main loop.
 *
 * QUEUE_DEFINE(name, type, capacity) defines name_t and its functions. The capacity is a power of
 * two up to 128, so the 8-bit head and tail can be read and written atomically on the AVR and
 * their difference is the fill level. The producer alone writes head and the overflow count, the
 * consumer alone writes tail. An item pushed into a full queue is dropped and counted: the
 * items already queued are kept in order.
 */
#ifndef RIG_QUEUE_H
#define RIG_QUEUE_H

#include <stdbool.h>
#include <stdint.h>

/* Keeps the compiler from moving item accesses across the index update. */
#define QUEUE_BARRIER() __asm__ __volatile__("" ::: "memory")

#define QUEUE_DEFINE(name, type, capacity)                                                        \
	_Static_assert((capacity) >= 2 && (capacity) <= 128 && ((capacity) & ((capacity) - 1)) == 0, \
		       #name " capacity must be a power of two from 2 to 128");                   \
	typedef struct {                                                                          \
		volatile uint8_t head;                                                            \
		volatile uint8_t tail;                                                            \
		volatile uint16_t overflow;                                                       \
		type items[capacity];                                                             \
	} name##_t;                                                                               \
	static inline uint8_t name##_count(const name##_t *queue)                                 \
	{                                                                                         \
		return (uint8_t)(queue->head - queue->tail);                                      \
	}                                                                                         \
	static inline bool name##_empty(const name##_t *queue)                                    \
	{                                                                                         \
		return queue->head == queue->tail;                                                \
	}                                                                                         \
	static inline uint8_t name##_free(const name##_t *queue)                                  \
	{                                                                                         \
		return (uint8_t)((capacity) - name##_count(queue));                               \
	}                                                                                         \
	static inline bool name##_push(name##_t *queue, type item)                                \
	{                                                                                         \
		uint8_t head = queue->head;                                                       \
		if ((uint8_t)(head - queue->tail) == (capacity)) {                                \
			queue->overflow++;                                                        \
			return false;                                                             \
		}                                                                                 \
		queue->items[head & ((capacity) - 1)] = item;                                     \
		QUEUE_BARRIER();                                                                  \
		queue->head = (uint8_t)(head + 1);                                                \
		return true;                                                                      \
	}                                                                                         \
	static inline bool name##_pop(name##_t *queue, type *item)                                \
	{                                                                                         \
		uint8_t tail = queue->tail;                                                       \
		if (queue->head == tail)                                                          \
			return false;                                                             \
		*item = queue->items[tail & ((capacity) - 1)];                                    \
		QUEUE_BARRIER();                                                                  \
		queue->tail = (uint8_t)(tail + 1);                                                \
		return true;                                                                      \
	}

#endif
