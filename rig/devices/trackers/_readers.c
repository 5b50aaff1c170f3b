/* Tracker reader threads in C. Each reads its source on a thread of its own (pthreads), stamps
 * what arrives with CLOCK_MONOTONIC and queues it, until the source ends, fails or stop(). They
 * never touch the GIL, so at 1000 records a second the interpreter is not woken once per record:
 * the Python side takes everything queued in one call. A stamp is a rig time, (monotonic ns -
 * origin_ns) / 1e9: a MonotonicClock's time line to the last bit where origin_ns is its own, any
 * other clock's where origin_ns is measured against it (rig.devices.trackers.transport). The
 * thread's CPU time and how it ended are kept for the Python side; stop(), or dropping the object,
 * ends and joins it.
 *
 * FdReader(fd, origin_ns): a file descriptor (a serial device, a pty, a socket), waited on with
 * poll and read whole at each wake-up; a chunk is what one read gave.
 *
 * LslReader(pull_sample_d, inlet, channels, origin_ns, keep): an LSL inlet, pulled one sample at a
 * time with liblsl's lsl_pull_sample_d (its address, from the library the caller loaded, and the
 * inlet's handle); a chunk is one sample, the tuple (LSL stamp, value, value, ...). `keep` (the
 * Python inlet) is held until the thread is joined, so the inlet outlives it. */

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
/* The longest an LSL pull waits, so that the thread notices stop(): liblsl's wait cannot be woken. */
#define LSL_PULL_TIMEOUT_S 0.05
#define MOST_CHANNELS 64
/* The threads' names, as top -H and /proc/PID/task/TID/comm show them (15 characters at most). */
#define FD_THREAD_NAME "rig fd reader"
#define LSL_THREAD_NAME "rig lsl reader"

enum outcome { RUNNING, STOPPED, END_OF_FILE, FAILED };
static const char *OUTCOME_NAMES[] = {NULL, "stopped", "end of file", "error"};

typedef double (*PullSample)(void *inlet, double *buffer, int32_t elements, double timeout, int32_t *error);

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
    int64_t origin_ns;
    /* An FdReader's: */
    int fd;
    int wake[2]; /* stop() writes to wake[1]; the thread polls wake[0] beside fd */
    /* An LslReader's: */
    PullSample pull;
    void *inlet;
    int channels;
    PyObject *keep;
    int stop_requested; /* atomic: set by stop(), read by the pulling thread between pulls */
    PyObject *(*chunk_of)(const void *self, const char *data, size_t size); /* a queued chunk as Python's */
    pthread_t thread;
    int started, joined, stopping; /* touched with the GIL held */
    pthread_mutex_t lock;
    pthread_cond_t changed; /* a chunk was queued, or the thread ended */
    /* Under lock: */
    Queue queue;
    enum outcome outcome;
    int error;     /* where the outcome is FAILED: errno (FdReader), liblsl's error code (LslReader) */
    double cpu_s;  /* the thread's CPU time, once it has ended */
    int waiters;
} Reader;

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

/* Queues a chunk stamped now, waking a waiting consumer; 0 where memory ran out. */
static int queue_chunk(Reader *r, const char *data, size_t size, int64_t stamp_ns) {
    pthread_mutex_lock(&r->lock);
    int queued = queue_append(&r->queue, data, size, stamp_ns);
    if (r->waiters) pthread_cond_broadcast(&r->changed);
    pthread_mutex_unlock(&r->lock);
    return queued;
}

/* The thread's last act: how it ended, and the CPU time it used, for the Python side. */
static void finish(Reader *r, enum outcome outcome, int error) {
    double cpu_s = seconds_of(CLOCK_THREAD_CPUTIME_ID);
    pthread_mutex_lock(&r->lock);
    r->outcome = outcome;
    r->error = error;
    r->cpu_s = cpu_s;
    pthread_cond_broadcast(&r->changed);
    pthread_mutex_unlock(&r->lock);
}

static void *read_loop(void *arg) {
    Reader *r = arg;
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
        } else if (!queue_chunk(r, buffer, (size_t)got, stamp_ns)) {
            outcome = FAILED;
            error = ENOMEM;
        }
    }
    free(buffer);
    finish(r, outcome, error);
    return NULL;
}

/* Pulls samples until stop() or an error; a chunk queued is the sample's LSL stamp, then its values. */
static void *pull_loop(void *arg) {
    Reader *r = arg;
    double sample[1 + MOST_CHANNELS];
    enum outcome outcome = RUNNING;
    int32_t error = 0;
    while (!__atomic_load_n(&r->stop_requested, __ATOMIC_ACQUIRE)) {
        error = 0;
        double stamp = r->pull(r->inlet, sample + 1, r->channels, LSL_PULL_TIMEOUT_S, &error);
        int64_t stamp_ns = monotonic_ns();
        if (error && error != -1) { /* -1: lsl_timeout_error, nothing came in time */
            outcome = FAILED;
            break;
        }
        if (stamp == 0.0) continue;
        sample[0] = stamp;
        if (!queue_chunk(r, (const char *)sample, (size_t)(1 + r->channels) * sizeof(double), stamp_ns)) {
            outcome = FAILED;
            error = ENOMEM;
            break;
        }
    }
    finish(r, outcome == RUNNING ? STOPPED : outcome, error);
    return NULL;
}

static PyObject *bytes_of(const void *self, const char *data, size_t size) {
    return PyBytes_FromStringAndSize(data, (Py_ssize_t)size);
}

/* (LSL stamp, value, value, ...): a pulled sample as the LSL decoder reads it. */
static PyObject *sample_of(const void *self, const char *data, size_t size) {
    const double *sample = (const double *)data;
    Py_ssize_t count = (Py_ssize_t)(size / sizeof(double));
    PyObject *result = PyTuple_New(count);
    if (!result) return NULL;
    for (Py_ssize_t i = 0; i < count; i++) {
        PyObject *value = PyFloat_FromDouble(sample[i]);
        if (!value) {
            Py_DECREF(result);
            return NULL;
        }
        PyTuple_SET_ITEM(result, i, value);
    }
    return result;
}

/* Starts the thread, named before the constructor returns (so that it is found by name at once). */
static int start_thread(Reader *self, void *(*loop)(void *), const char *name) {
    self->outcome = RUNNING;
    int failed = pthread_create(&self->thread, NULL, loop, self);
    if (failed) {
        self->outcome = STOPPED;
        errno = failed;
        PyErr_SetFromErrno(PyExc_OSError);
        return -1;
    }
    pthread_setname_np(self->thread, name);
    self->started = 1;
    return 0;
}

static int FdReader_init(Reader *self, PyObject *args, PyObject *kwargs) {
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
    self->chunk_of = bytes_of;
    return start_thread(self, read_loop, FD_THREAD_NAME);
}

static int LslReader_init(Reader *self, PyObject *args, PyObject *kwargs) {
    static char *keywords[] = {"pull_sample_d", "inlet", "channels", "origin_ns", "keep", NULL};
    unsigned long long pull, inlet;
    long long origin_ns;
    PyObject *keep;
    if (self->started) {
        PyErr_SetString(PyExc_RuntimeError, "an LslReader is started once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwargs, "KKiLO:LslReader", keywords, &pull, &inlet, &self->channels, &origin_ns, &keep))
        return -1;
    if (!pull || !inlet) {
        PyErr_SetString(PyExc_ValueError, "the function's address and the inlet's handle must not be null");
        return -1;
    }
    if (self->channels < 1 || self->channels > MOST_CHANNELS) {
        PyErr_Format(PyExc_ValueError, "channels must be 1 to %d", MOST_CHANNELS);
        return -1;
    }
    self->pull = (PullSample)(uintptr_t)pull;
    self->inlet = (void *)(uintptr_t)inlet;
    self->origin_ns = origin_ns;
    Py_INCREF(keep);
    self->keep = keep;
    self->chunk_of = sample_of;
    return start_thread(self, pull_loop, LSL_THREAD_NAME);
}

static PyObject *Reader_new(PyTypeObject *type, PyObject *args, PyObject *kwargs) {
    Reader *self = (Reader *)type->tp_alloc(type, 0);
    if (!self) return NULL;
    self->wake[0] = self->wake[1] = -1;
    self->outcome = STOPPED; /* until a thread is started: nothing to wait for */
    pthread_mutex_init(&self->lock, NULL);
    pthread_condattr_t attributes;
    pthread_condattr_init(&attributes);
    pthread_condattr_setclock(&attributes, CLOCK_MONOTONIC);
    pthread_cond_init(&self->changed, &attributes);
    pthread_condattr_destroy(&attributes);
    return (PyObject *)self;
}

/* Ends the thread and joins it; the GIL is released while it waits. */
static void stop_thread(Reader *self) {
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
    __atomic_store_n(&self->stop_requested, 1, __ATOMIC_RELEASE);
    if (self->wake[1] >= 0) {
        ssize_t written;
        do written = write(self->wake[1], "x", 1);
        while (written < 0 && errno == EINTR);
    }
    Py_BEGIN_ALLOW_THREADS
    pthread_join(self->thread, NULL);
    Py_END_ALLOW_THREADS
    self->joined = 1;
}

static void Reader_dealloc(Reader *self) {
    stop_thread(self);
    Py_CLEAR(self->keep);
    if (self->wake[0] >= 0) close(self->wake[0]);
    if (self->wake[1] >= 0) close(self->wake[1]);
    queue_free(&self->queue);
    pthread_mutex_destroy(&self->lock);
    pthread_cond_destroy(&self->changed);
    Py_TYPE(self)->tp_free((PyObject *)self);
}

static PyObject *Reader_stop(Reader *self, PyObject *unused) {
    stop_thread(self);
    Py_RETURN_NONE;
}

static PyObject *Reader_take(Reader *self, PyObject *unused) {
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
        PyObject *chunk = self->chunk_of(self, taken.bytes + start, taken.ends[i] - start);
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
static int wait_for(Reader *self, double timeout_s, int for_data) {
    /* Longer than a few decades is as good as forever (and keeps the sum in range). */
    int64_t deadline_ns = timeout_s < 0 || timeout_s > 1e9 ? INT64_MAX : monotonic_ns() + (int64_t)(timeout_s * 1e9);
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

static PyObject *wait_method(Reader *self, PyObject *args, int for_data) {
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

static PyObject *Reader_wait(Reader *self, PyObject *args) { return wait_method(self, args, 1); }

static PyObject *Reader_wait_ended(Reader *self, PyObject *args) { return wait_method(self, args, 0); }

static PyObject *Reader_get_outcome(Reader *self, void *unused) {
    pthread_mutex_lock(&self->lock);
    enum outcome outcome = self->outcome;
    pthread_mutex_unlock(&self->lock);
    if (outcome == RUNNING) Py_RETURN_NONE;
    return PyUnicode_FromString(OUTCOME_NAMES[outcome]);
}

static PyObject *Reader_get_errno(Reader *self, void *unused) {
    pthread_mutex_lock(&self->lock);
    int error = self->error;
    pthread_mutex_unlock(&self->lock);
    return PyLong_FromLong(error);
}

static PyObject *Reader_get_cpu_s(Reader *self, void *unused) {
    pthread_mutex_lock(&self->lock);
    double cpu_s = self->cpu_s;
    if (self->outcome == RUNNING) { /* still running, so its clock is still there */
        clockid_t clock;
        if (pthread_getcpuclockid(self->thread, &clock) == 0) cpu_s = seconds_of(clock);
    }
    pthread_mutex_unlock(&self->lock);
    return PyFloat_FromDouble(cpu_s);
}

static PyMethodDef Reader_methods[] = {
    {"take", (PyCFunction)Reader_take, METH_NOARGS,
     "take() -> (chunks, arrivals): every chunk queued since the last take, in order, and the rig\n"
     "time (s) each arrived at."},
    {"wait", (PyCFunction)Reader_wait, METH_VARARGS,
     "wait(timeout_s=None) -> bool: waits, the GIL released, until there is a chunk to take or the\n"
     "thread has ended (True), or the timeout passed (False; None waits forever)."},
    {"wait_ended", (PyCFunction)Reader_wait_ended, METH_VARARGS,
     "wait_ended(timeout_s=None) -> bool: waits, the GIL released, until the thread has ended (True)\n"
     "or the timeout passed (False; None waits forever)."},
    {"stop", (PyCFunction)Reader_stop, METH_NOARGS,
     "stop(): ends the thread, if it still runs, and joins it; what it read stays to be taken."},
    {NULL, NULL, 0, NULL},
};

static PyGetSetDef Reader_getset[] = {
    {"outcome", (getter)Reader_get_outcome, NULL,
     "None while the thread runs; then how it ended: \"stopped\", \"end of file\" or \"error\".", NULL},
    {"errno", (getter)Reader_get_errno, NULL,
     "Where the outcome is \"error\", the failed call's errno (FdReader) or liblsl's error code\n"
     "(LslReader); else 0.", NULL},
    {"cpu_s", (getter)Reader_get_cpu_s, NULL, "The CPU time (s) the thread has used.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject FdReaderType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "rig.devices.trackers._readers.FdReader",
    .tp_doc = "FdReader(fd, origin_ns): reads fd on a thread of its own, each chunk (bytes) stamped on\n"
              "the monotonic clock as (ns - origin_ns) / 1e9, until its end, an error or stop().\n"
              "The descriptor stays the caller's: keep it open until the thread is stopped.",
    .tp_basicsize = sizeof(Reader),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = Reader_new,
    .tp_init = (initproc)FdReader_init,
    .tp_dealloc = (destructor)Reader_dealloc,
    .tp_methods = Reader_methods,
    .tp_getset = Reader_getset,
};

static PyTypeObject LslReaderType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "rig.devices.trackers._readers.LslReader",
    .tp_doc = "LslReader(pull_sample_d, inlet, channels, origin_ns, keep): pulls the LSL inlet (liblsl's\n"
              "lsl_pull_sample_d at that address, the inlet's handle) on a thread of its own, each sample\n"
              "a chunk (LSL stamp, values...) stamped on the monotonic clock as (ns - origin_ns) /\n"
              "1e9, until liblsl reports an error or stop(); `keep` (the inlet) is held until then.",
    .tp_basicsize = sizeof(Reader),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_new = Reader_new,
    .tp_init = (initproc)LslReader_init,
    .tp_dealloc = (destructor)Reader_dealloc,
    .tp_methods = Reader_methods,
    .tp_getset = Reader_getset,
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_readers", "Tracker reader threads in C.", -1, NULL,
};

static int add_type(PyObject *m, PyTypeObject *type, const char *name) {
    if (PyType_Ready(type) < 0) return -1;
    Py_INCREF(type);
    if (PyModule_AddObject(m, name, (PyObject *)type) < 0) {
        Py_DECREF(type);
        return -1;
    }
    return 0;
}

PyMODINIT_FUNC PyInit__readers(void) {
    PyObject *m = PyModule_Create(&module);
    if (!m) return NULL;
    if (add_type(m, &FdReaderType, "FdReader") < 0 || add_type(m, &LslReaderType, "LslReader") < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
