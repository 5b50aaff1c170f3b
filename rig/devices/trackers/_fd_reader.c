/* A tracker's file descriptor (a serial device, a pty, a socket) read in C, two ways:
 *
 * FdReader(fd, origin_ns): a thread of its own (pthreads) that waits for fd to be readable, reads
 * what it holds, stamps the chunk with CLOCK_MONOTONIC and queues it, until the end of the file, a
 * read error or stop(). It never touches the GIL, so at 1000 records a second the interpreter is
 * not woken once per record: the Python side takes everything queued in one call. A chunk's stamp
 * is a rig time, (monotonic ns - origin_ns) / 1e9, which is MonotonicClock's time line (the
 * system's monotonic clock, counted from its origin_ns) to the last bit. The thread's CPU time and
 * how it ended are kept for the Python side; stop(), or dropping the object, ends and joins it.
 *
 * wait_read(fd, timeout_ms, size): one wait and read in one call that releases the GIL once, for a
 * reader thread in Python (where the stamps are on another clock than the system's). The bytes,
 * b"" at the end of the file, None if nothing came in time (or a signal interrupted the wait);
 * OSError as os.read raises it. */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <stdint.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define MOST_BYTES 65536
#define NS_PER_S 1000000000LL
/* The longest a wait sleeps with the GIL released before it looks for a signal (Ctrl-C). */
#define SIGNAL_CHECK_NS 100000000LL

static PyObject *wait_read(PyObject *self, PyObject *args) {
    int fd, timeout_ms;
    Py_ssize_t size;
    if (!PyArg_ParseTuple(args, "iin:wait_read", &fd, &timeout_ms, &size)) return NULL;
    if (size < 0) {
        PyErr_SetString(PyExc_ValueError, "size must not be negative");
        return NULL;
    }
    if (size > MOST_BYTES) size = MOST_BYTES;
    char buffer[MOST_BYTES];
    struct pollfd wanted = {fd, POLLIN, 0};
    int ready;
    ssize_t got = 0;
    int error = 0;
    Py_BEGIN_ALLOW_THREADS
    ready = poll(&wanted, 1, timeout_ms);
    if (ready > 0) {
        got = read(fd, buffer, (size_t)size);
        if (got < 0) error = errno;
    } else if (ready < 0) {
        error = errno;
    }
    Py_END_ALLOW_THREADS
    if (error == EINTR || error == EAGAIN) {
        if (PyErr_CheckSignals() < 0) return NULL;
        Py_RETURN_NONE;
    }
    if (error) {
        errno = error;
        return PyErr_SetFromErrno(PyExc_OSError);
    }
    if (ready == 0) Py_RETURN_NONE;
    return PyBytes_FromStringAndSize(buffer, got);
}

enum outcome { RUNNING, STOPPED, END_OF_FILE, FAILED };
static const char *OUTCOME_NAMES[] = {NULL, "stopped", "end of file", "error"};

/* Chunks queued by the thread, not yet taken: their bytes end to end, where each ends, its stamp. */
typedef struct {
    char *bytes;
    size_t used, capacity;
    size_t *ends;
    int64_t *stamps_ns;
    size_t count, slots;
} Queue;

typedef struct {
    PyObject_HEAD
    int fd;
    int64_t origin_ns;
    int wake[2]; /* stop() writes to wake[1]; the thread polls wake[0] beside fd */
    pthread_t thread;
    int started, joined, stopping; /* touched with the GIL held */
    pthread_mutex_t lock;
    pthread_cond_t changed; /* a chunk was queued, or the thread ended */
    /* Under lock: */
    Queue queue;
    enum outcome outcome;
    int error;     /* errno, where the outcome is FAILED */
    double cpu_s;  /* the thread's CPU time, once it has ended */
    int waiters;
} FdReader;

static int64_t monotonic_ns(void) {
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (int64_t)now.tv_sec * NS_PER_S + now.tv_nsec;
}

static double seconds_of(clockid_t clock) {
    struct timespec t;
    if (clock_gettime(clock, &t) != 0) return -1.0;
    return (double)t.tv_sec + (double)t.tv_nsec / 1e9;
}

/* Appends a chunk; 0 where memory ran out. */
static int queue_append(Queue *q, const char *data, size_t size, int64_t stamp_ns) {
    if (q->used + size > q->capacity) {
        size_t capacity = q->capacity ? q->capacity : 4096;
        while (capacity < q->used + size) capacity *= 2;
        char *bytes = realloc(q->bytes, capacity);
        if (!bytes) return 0;
        q->bytes = bytes;
        q->capacity = capacity;
    }
    if (q->count == q->slots) {
        size_t slots = q->slots ? 2 * q->slots : 64;
        size_t *ends = realloc(q->ends, slots * sizeof *ends);
        if (!ends) return 0;
        q->ends = ends;
        int64_t *stamps = realloc(q->stamps_ns, slots * sizeof *stamps);
        if (!stamps) return 0;
        q->stamps_ns = stamps;
        q->slots = slots;
    }
    memcpy(q->bytes + q->used, data, size);
    q->used += size;
    q->ends[q->count] = q->used;
    q->stamps_ns[q->count] = stamp_ns;
    q->count++;
    return 1;
}

static void queue_free(Queue *q) {
    free(q->bytes);
    free(q->ends);
    free(q->stamps_ns);
    memset(q, 0, sizeof *q);
}

static void *read_loop(void *arg) {
    FdReader *r = arg;
    enum outcome outcome = RUNNING;
    int error = 0;
    char *buffer = malloc(MOST_BYTES);
    if (!buffer) {
        outcome = FAILED;
        error = ENOMEM;
    }
    struct pollfd wanted[2] = {{r->fd, POLLIN, 0}, {r->wake[0], POLLIN, 0}};
    while (outcome == RUNNING) {
        if (poll(wanted, 2, -1) < 0) {
            if (errno == EINTR) continue;
            outcome = FAILED;
            error = errno;
            break;
        }
        if (wanted[1].revents) {
            outcome = STOPPED;
            break;
        }
        if (!wanted[0].revents) continue;
        ssize_t got = read(r->fd, buffer, MOST_BYTES);
        int64_t stamp_ns = monotonic_ns();
        if (got < 0) {
            if (errno == EINTR || errno == EAGAIN) continue;
            outcome = FAILED;
            error = errno;
        } else if (got == 0) {
            outcome = END_OF_FILE;
        } else {
            pthread_mutex_lock(&r->lock);
            int queued = queue_append(&r->queue, buffer, (size_t)got, stamp_ns);
            if (r->waiters) pthread_cond_broadcast(&r->changed);
            pthread_mutex_unlock(&r->lock);
            if (!queued) {
                outcome = FAILED;
                error = ENOMEM;
            }
        }
    }
    free(buffer);
    double cpu_s = seconds_of(CLOCK_THREAD_CPUTIME_ID);
    pthread_mutex_lock(&r->lock);
    r->outcome = outcome;
    r->error = error;
    r->cpu_s = cpu_s;
    pthread_cond_broadcast(&r->changed);
    pthread_mutex_unlock(&r->lock);
    return NULL;
}

static int FdReader_init(FdReader *self, PyObject *args, PyObject *kwargs) {
    static char *keywords[] = {"fd", "origin_ns", NULL};
    long long origin_ns;
    if (self->started) {
        PyErr_SetString(PyExc_RuntimeError, "an FdReader is started once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "iL:FdReader", keywords, &self->fd, &origin_ns)) return -1;
    self->origin_ns = origin_ns;
    if (fcntl(self->fd, F_GETFD) == -1 || pipe(self->wake) != 0) {
        PyErr_SetFromErrno(PyExc_OSError);
        return -1;
    }
    fcntl(self->wake[0], F_SETFD, FD_CLOEXEC);
    fcntl(self->wake[1], F_SETFD, FD_CLOEXEC);
    int failed = pthread_create(&self->thread, NULL, read_loop, self);
    if (failed) {
        close(self->wake[0]);
        close(self->wake[1]);
        self->wake[0] = self->wake[1] = -1;
        errno = failed;
        PyErr_SetFromErrno(PyExc_OSError);
        return -1;
    }
    self->started = 1;
    return 0;
}

static PyObject *FdReader_new(PyTypeObject *type, PyObject *args, PyObject *kwargs) {
    FdReader *self = (FdReader *)type->tp_alloc(type, 0);
    if (!self) return NULL;
    self->wake[0] = self->wake[1] = -1;
    pthread_mutex_init(&self->lock, NULL);
    pthread_condattr_t attributes;
    pthread_condattr_init(&attributes);
    pthread_condattr_setclock(&attributes, CLOCK_MONOTONIC);
    pthread_cond_init(&self->changed, &attributes);
    pthread_condattr_destroy(&attributes);
    return (PyObject *)self;
}

/* Ends the thread and joins it; the GIL is released while it waits. */
static void stop_thread(FdReader *self) {
    if (!self->started || self->joined) return;
    if (self->stopping) { /* another Python thread is joining it: wait for the end it is waiting for */
        Py_BEGIN_ALLOW_THREADS
        pthread_mutex_lock(&self->lock);
        while (self->outcome == RUNNING) pthread_cond_wait(&self->changed, &self->lock);
        pthread_mutex_unlock(&self->lock);
        Py_END_ALLOW_THREADS
        return;
    }
    self->stopping = 1;
    ssize_t written;
    do written = write(self->wake[1], "x", 1);
    while (written < 0 && errno == EINTR);
    Py_BEGIN_ALLOW_THREADS
    pthread_join(self->thread, NULL);
    Py_END_ALLOW_THREADS
    self->joined = 1;
}

static void FdReader_dealloc(FdReader *self) {
    stop_thread(self);
    if (self->wake[0] >= 0) close(self->wake[0]);
    if (self->wake[1] >= 0) close(self->wake[1]);
    queue_free(&self->queue);
    pthread_mutex_destroy(&self->lock);
    pthread_cond_destroy(&self->changed);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *FdReader_stop(FdReader *self, PyObject *unused) {
    stop_thread(self);
    Py_RETURN_NONE;
}

static PyObject *FdReader_take(FdReader *self, PyObject *unused) {
    pthread_mutex_lock(&self->lock);
    Queue taken = self->queue;
    memset(&self->queue, 0, sizeof self->queue);
    pthread_mutex_unlock(&self->lock);
    PyObject *chunks = PyList_New((Py_ssize_t)taken.count);
    PyObject *arrivals = PyList_New((Py_ssize_t)taken.count);
    PyObject *result = NULL;
    if (!chunks || !arrivals) goto done;
    size_t start = 0;
    for (size_t i = 0; i < taken.count; i++) {
        PyObject *chunk = PyBytes_FromStringAndSize(taken.bytes + start, (Py_ssize_t)(taken.ends[i] - start));
        if (!chunk) goto done;
        PyList_SET_ITEM(chunks, (Py_ssize_t)i, chunk);
        PyObject *arrival = PyFloat_FromDouble((double)(taken.stamps_ns[i] - self->origin_ns) / 1e9);
        if (!arrival) goto done;
        PyList_SET_ITEM(arrivals, (Py_ssize_t)i, arrival);
        start = taken.ends[i];
    }
    result = PyTuple_Pack(2, chunks, arrivals);
done:
    Py_XDECREF(chunks);
    Py_XDECREF(arrivals);
    queue_free(&taken);
    return result;
}

/* Waits up to timeout_s (forever if negative) until there is a chunk to take (`for_data`) or until
 * the thread has ended; 1 if so, 0 if the time ran out, -1 with an exception set by a signal's
 * handler (Ctrl-C). */
static int wait_for(FdReader *self, double timeout_s, int for_data) {
    int64_t deadline_ns = timeout_s < 0 ? INT64_MAX : monotonic_ns() + (int64_t)(timeout_s * 1e9);
    for (;;) {
        int done;
        int64_t now_ns;
        Py_BEGIN_ALLOW_THREADS
        pthread_mutex_lock(&self->lock);
        self->waiters++;
        int64_t until_ns = monotonic_ns() + SIGNAL_CHECK_NS;
        if (until_ns > deadline_ns) until_ns = deadline_ns;
        struct timespec until = {(time_t)(until_ns / NS_PER_S), (long)(until_ns % NS_PER_S)};
        while (!(done = (self->outcome != RUNNING) || (for_data && self->queue.count)))
            if (pthread_cond_timedwait(&self->changed, &self->lock, &until) == ETIMEDOUT) break;
        self->waiters--;
        pthread_mutex_unlock(&self->lock);
        now_ns = monotonic_ns();
        Py_END_ALLOW_THREADS
        if (done) return 1;
        if (PyErr_CheckSignals() < 0) return -1;
        if (now_ns >= deadline_ns) return 0;
    }
}

static PyObject *wait_method(FdReader *self, PyObject *args, int for_data) {
    PyObject *timeout = Py_None;
    if (!PyArg_ParseTuple(args, "|O", &timeout)) return NULL;
    double timeout_s = -1.0;
    if (timeout != Py_None) {
        timeout_s = PyFloat_AsDouble(timeout);
        if (timeout_s == -1.0 && PyErr_Occurred()) return NULL;
        if (timeout_s < 0.0 || timeout_s != timeout_s) {
            PyErr_SetString(PyExc_ValueError, "timeout must be a number of seconds, 0 or more, or None");
            return NULL;
        }
    }
    int done = wait_for(self, timeout_s, for_data);
    if (done < 0) return NULL;
    return PyBool_FromLong(done);
}

static PyObject *FdReader_wait(FdReader *self, PyObject *args) { return wait_method(self, args, 1); }

static PyObject *FdReader_wait_ended(FdReader *self, PyObject *args) { return wait_method(self, args, 0); }

static PyObject *FdReader_get_outcome(FdReader *self, void *unused) {
    pthread_mutex_lock(&self->lock);
    enum outcome outcome = self->outcome;
    pthread_mutex_unlock(&self->lock);
    if (outcome == RUNNING) Py_RETURN_NONE;
    return PyUnicode_FromString(OUTCOME_NAMES[outcome]);
}

static PyObject *FdReader_get_errno(FdReader *self, void *unused) {
    pthread_mutex_lock(&self->lock);
    int error = self->error;
    pthread_mutex_unlock(&self->lock);
    return PyLong_FromLong(error);
}

static PyObject *FdReader_get_cpu_s(FdReader *self, void *unused) {
    pthread_mutex_lock(&self->lock);
    double cpu_s = self->cpu_s;
    if (self->outcome == RUNNING) { /* still running, so its clock is still there */
        clockid_t clock;
        if (pthread_getcpuclockid(self->thread, &clock) == 0) cpu_s = seconds_of(clock);
    }
    pthread_mutex_unlock(&self->lock);
    return PyFloat_FromDouble(cpu_s);
}

static PyMethodDef FdReader_methods[] = {
    {"take", (PyCFunction)FdReader_take, METH_NOARGS,
     "take() -> (chunks, arrivals): every chunk read since the last take, as bytes, in order, and the\n"
     "rig time (s) each was read at."},
    {"wait", (PyCFunction)FdReader_wait, METH_VARARGS,
     "wait(timeout_s=None) -> bool: waits, the GIL released, until there is a chunk to take or the\n"
     "thread has ended (True), or the timeout passed (False; None waits forever)."},
    {"wait_ended", (PyCFunction)FdReader_wait_ended, METH_VARARGS,
     "wait_ended(timeout_s=None) -> bool: waits, the GIL released, until the thread has ended (True)\n"
     "or the timeout passed (False; None waits forever)."},
    {"stop", (PyCFunction)FdReader_stop, METH_NOARGS,
     "stop(): ends the thread, if it still runs, and joins it; what it read stays to be taken."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef FdReader_getset[] = {
    {"outcome", (getter)FdReader_get_outcome, NULL,
     "None while the thread runs; then how it ended: \"stopped\", \"end of file\" or \"error\".", NULL},
    {"errno", (getter)FdReader_get_errno, NULL, "The read's or wait's errno where the outcome is \"error\", else 0.", NULL},
    {"cpu_s", (getter)FdReader_get_cpu_s, NULL, "The CPU time (s) the thread has used.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject FdReaderType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "rig.devices.trackers._fd_reader.FdReader",
    .tp_doc = "FdReader(fd, origin_ns): reads fd on a thread of its own, each chunk stamped on the\n"
              "monotonic clock as (ns - origin_ns) / 1e9, until its end, an error or stop().\n"
              "The descriptor stays the caller's: keep it open until the thread is stopped.",
    .tp_basicsize = sizeof(FdReader),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = FdReader_new,
    .tp_init = (initproc)FdReader_init,
    .tp_dealloc = (destructor)FdReader_dealloc,
    .tp_methods = FdReader_methods,
    .tp_getset = FdReader_getset,
};

static PyMethodDef methods[] = {
    {"wait_read", wait_read, METH_VARARGS,
     "wait_read(fd, timeout_ms, size): the bytes fd holds once readable, b\"\" at its end, None if nothing came in time."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_fd_reader", "A tracker's file descriptor read in C: by a thread of its own, or one wait and read per call.", -1,
    methods,
};

PyMODINIT_FUNC PyInit__fd_reader(void) {
    if (PyType_Ready(&FdReaderType) < 0) return NULL;
    PyObject *m = PyModule_Create(&module);
    if (!m) return NULL;
    Py_INCREF(&FdReaderType);
    if (PyModule_AddObject(m, "FdReader", (PyObject *)&FdReaderType) < 0) {
        Py_DECREF(&FdReaderType);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
