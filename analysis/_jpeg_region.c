/* Decode one rectangle of a JPEG image to grey, and no more of the image than that needs.
 *
 * After calibration the analyser looks at two ROIs, a band of a few rows of each frame. libjpeg-turbo
 * can skip the inverse DCT of the rows above the band (jpeg_skip_scanlines) and of the columns
 * beside it (jpeg_crop_scanline, to the nearest 8 or 16 pixels), and decoding stops after the
 * band's last row, so the entropy decoding of the rows below is skipped too. Grey output from a
 * colour JPEG takes its luma, with no chroma upsampling or colour conversion: the same pixels
 * OpenCV's imdecode(..., IMREAD_GRAYSCALE) gives, both being libjpeg with its default (islow) DCT.
 *
 * decode_grey(jpeg, top, left, out, height, width) -> bool writes rows top..top+height and
 * columns left..left+width into the C-contiguous uint8 buffer out; False means the data is not a
 * JPEG libjpeg can decode cleanly as far as the rectangle's last row, or the rectangle is not
 * inside the image (the caller then decodes the whole image its usual way, which reports what is
 * wrong). Data damaged only below the rectangle is never read, so it is no reason to refuse.
 * The GIL is released while decoding.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jpeglib.h>

struct jump_error {
    struct jpeg_error_mgr manager;
    jmp_buf jump;
};

static void jump_out(j_common_ptr info) { longjmp(((struct jump_error *)info->err)->jump, 1); }

/* A warning (level -1) means corrupt or truncated data that libjpeg would patch over; OpenCV
 * refuses such images, so this does too. Trace messages (level >= 0) are ignored. */
static void refuse_warnings(j_common_ptr info, int level) {
    if (level < 0) {
        jump_out(info);
    }
}

static int decode_rectangle(const unsigned char *jpeg, unsigned long size, int top, int left, int height,
                            int width, unsigned char *out) {
    struct jpeg_decompress_struct info;
    struct jump_error error;
    JSAMPLE *volatile row = NULL;
    info.err = jpeg_std_error(&error.manager);
    error.manager.error_exit = jump_out;
    error.manager.emit_message = refuse_warnings;
    if (setjmp(error.jump)) {
        free(row);
        jpeg_destroy_decompress(&info);
        return 0;
    }
    jpeg_create_decompress(&info);
    jpeg_mem_src(&info, jpeg, size);
    jpeg_read_header(&info, TRUE);
    if (top < 0 || left < 0 || height <= 0 || width <= 0 || (JDIMENSION)(top + height) > info.image_height ||
        (JDIMENSION)(left + width) > info.image_width) {
        jpeg_destroy_decompress(&info);
        return 0;
    }
    info.out_color_space = JCS_GRAYSCALE;
    jpeg_start_decompress(&info);
    JDIMENSION first_column = (JDIMENSION)left, columns = (JDIMENSION)width;
    jpeg_crop_scanline(&info, &first_column, &columns);
    row = malloc(info.output_width);
    if (row == NULL) {
        jpeg_destroy_decompress(&info);
        return 0;
    }
    if (top > 0 && jpeg_skip_scanlines(&info, (JDIMENSION)top) != (JDIMENSION)top) {
        longjmp(error.jump, 1);
    }
    size_t shift = (size_t)left - first_column;
    for (int y = 0; y < height; y++) {
        JSAMPROW rows[1] = {row};
        if (jpeg_read_scanlines(&info, rows, 1) != 1) {
            longjmp(error.jump, 1);
        }
        memcpy(out + (size_t)y * (size_t)width, row + shift, (size_t)width);
    }
    free(row);
    jpeg_abort_decompress(&info);
    jpeg_destroy_decompress(&info);
    return 1;
}

static PyObject *decode_grey(PyObject *module, PyObject *args) {
    (void)module;
    Py_buffer jpeg, out;
    int top, left, height, width;
    if (!PyArg_ParseTuple(args, "y*iiw*ii", &jpeg, &top, &left, &out, &height, &width)) {
        return NULL;
    }
    if (height < 0 || width < 0 || out.len != (Py_ssize_t)height * width || !PyBuffer_IsContiguous(&out, 'C')) {
        PyBuffer_Release(&jpeg);
        PyBuffer_Release(&out);
        PyErr_SetString(PyExc_ValueError, "out must be a C-contiguous buffer of height * width bytes");
        return NULL;
    }
    int decoded;
    Py_BEGIN_ALLOW_THREADS
    decoded = decode_rectangle(jpeg.buf, (unsigned long)jpeg.len, top, left, height, width, out.buf);
    Py_END_ALLOW_THREADS
    PyBuffer_Release(&jpeg);
    PyBuffer_Release(&out);
    return PyBool_FromLong(decoded);
}

static PyMethodDef methods[] = {
    {"decode_grey", decode_grey, METH_VARARGS,
     "decode_grey(jpeg, top, left, out, height, width) -> bool: decode one rectangle of a JPEG to grey."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_jpeg_region", NULL, -1, methods};

PyMODINIT_FUNC PyInit__jpeg_region(void) { return PyModule_Create(&module); }
