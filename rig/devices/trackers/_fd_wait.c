/* wait_read(fd, timeout_ms, size): what a serial tracker's reader thread does at every wake-up, in
 * one call that releases the GIL once. Waits up to timeout_ms for fd to be readable and reads what
 * it holds, at most size bytes (and at most 64 KiB): the bytes, b"" at the end of the file (the
 * other end went away), None if nothing came in time (or a signal interrupted the wait). OSError
 * as os.read raises it. The same as select.poll() then os.read(), without the two round trips
 * through the interpreter and the GIL that those cost per record. */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <errno.h>
#include <poll.h>
#include <unistd.h>

#define MOST_BYTES 65536

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

static PyMethodDef methods[] = {
    {"wait_read", wait_read, METH_VARARGS,
     "wait_read(fd, timeout_ms, size): the bytes fd holds once readable, b\"\" at its end, None if nothing came in time."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_fd_wait", "A file descriptor waited on and read in one call.", -1, methods};

PyMODINIT_FUNC PyInit__fd_wait(void) { return PyModule_Create(&module); }
