/*
 * c_module.c - the Python entry of a component written in C.
 *
 * Compiled together with the component's own C files (which are built
 * with HALSDK_API_EXTERN so that they share this file's API pointer).
 * HALSDK_MODULE_NAME is the module (and component) name.  The module
 * offers what the halsdk loader expects of any component module:
 *   modparams  {name: (kind, default, description)}, from RTAPI_MP_*
 *   setup(**params)  sets the parameters, then calls rtapi_app_main()
 *   cleanup()        calls rtapi_app_exit()
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "halsdk_api.h"
#include "halsdk_module.h"

/* built with HALSDK_API_EXTERN like the component's files: define the
   shared API pointer here */
const halsdk_api *halsdk_api_ptr;

#define CAT2_(a, b) a##b
#define CAT_(a, b) CAT2_(a, b)
#define STR2_(a) #a
#define STR_(a) STR2_(a)

const char halsdk_module_name[] = STR_(HALSDK_MODULE_NAME);

/* EXPORT_SYMBOL entries of the module */
#define MAX_EXPORTS 64
static struct {
    const char *name;
    void *addr;
} exports[MAX_EXPORTS];
static int nexports;
static int export_overflow;

void halsdk_symbol_register(const char *name, void *addr)
{
    if (nexports >= MAX_EXPORTS) {
        export_overflow = 1;
        return;
    }
    exports[nexports].name = name;
    exports[nexports].addr = addr;
    nexports++;
}

/* offer the module's symbols; on a failure none stays exported */
static int export_symbols(void)
{
    for (int i = 0; i < nexports; i++) {
        int r = halsdk_api_ptr->symbol_export(exports[i].name,
                                              exports[i].addr,
                                              halsdk_module_name);
        if (r < 0) {
            halsdk_api_ptr->symbol_drop(halsdk_module_name);
            return r;
        }
    }
    return 0;
}

/* ---------------------------------------------- rtapi_shmem_* (rtapi.h)
   A block of key K is the instance's shared block "shm.KKKKKKKK" (hex,
   the name the Python hal.shm(comp, K, size) of halsdk.compat uses too);
   the module knows it by an id, its index in this table plus one. */
#define MAX_SHMEM 64
static long long shmem_handle[MAX_SHMEM];      /* handle + 1; 0: free */

int rtapi_shmem_new(int key, int module_id, unsigned long int size)
{
    char name[32];
    if (size == 0 || size > (unsigned long)LONG_MAX)
        return -EINVAL;
    snprintf(name, sizeof(name), "shm.%08x", (unsigned)key);
    long long h = halsdk_api_ptr->shmem_attach(name);
    if (h < 0) {
        h = halsdk_api_ptr->shmem_new(name, module_id, (long)size);
        if (h == -EEXIST)
            h = halsdk_api_ptr->shmem_attach(name);
    }
    if (h < 0)
        return (int)h;
    if (halsdk_api_ptr->shmem_size(h) < (long)size) {
        return -EINVAL;         /* made smaller by its first user */
    }
    for (int i = 0; i < MAX_SHMEM; i++) {
        if (!shmem_handle[i]) {
            shmem_handle[i] = h + 1;
            return i + 1;
        }
    }
    return -ENOMEM;
}

static long long shmem_of(int shmem_id)
{
    if (shmem_id < 1 || shmem_id > MAX_SHMEM || !shmem_handle[shmem_id - 1])
        return -1;
    return shmem_handle[shmem_id - 1] - 1;
}

int rtapi_shmem_delete(int shmem_id, int module_id)
{
    (void)module_id;
    if (shmem_of(shmem_id) < 0)
        return -EINVAL;
    /* the block itself goes with the component that made it */
    shmem_handle[shmem_id - 1] = 0;
    return 0;
}

int rtapi_shmem_getptr(int shmem_id, void **ptr)
{
    long long h = shmem_of(shmem_id);
    void *p = h < 0 ? NULL : halsdk_api_ptr->shmem_ptr(h);
    if (!p)
        return -EINVAL;
    *ptr = p;
    return 0;
}

/* ------------------------------------------ hal_set_constructor (hal.h) */
typedef int (*constructor)(char *prefix, char *arg);
static constructor make_instance;
static int make_comp;

int hal_set_constructor(int comp_id, constructor make)
{
    if (!halsdk_api_ptr->comp_name(comp_id))
        return -EINVAL;
    make_instance = make;
    make_comp = comp_id;
    return 0;
}

static halsdk_modparam_t modparams[HALSDK_MAX_MODPARAMS];
static void *defaults[HALSDK_MAX_MODPARAMS];    /* values at import */
static int nmodparams;
static int mp_overflow;

static size_t param_bytes(const halsdk_modparam_t *m)
{
    size_t one = (m->kind == 'i' || m->kind == 'I') ? sizeof(int)
                 : (m->kind == 'l' || m->kind == 'L') ? sizeof(long)
                 : sizeof(char *);
    return one * (size_t)(m->count > 0 ? m->count : 1);
}

/* a module is imported once per process but may be loaded again after
   an unload: every load starts from the parameters' initial values */
static int save_defaults(void)
{
    for (int i = 0; i < nmodparams; i++) {
        defaults[i] = malloc(param_bytes(&modparams[i]));
        if (!defaults[i])
            return -1;
        memcpy(defaults[i], modparams[i].addr, param_bytes(&modparams[i]));
    }
    return 0;
}

static void restore_defaults(void)
{
    for (int i = 0; i < nmodparams; i++)
        if (defaults[i])
            memcpy(modparams[i].addr, defaults[i],
                   param_bytes(&modparams[i]));
}

void halsdk_modparam_register(const char *name, char kind, void *addr,
                              int count, const char *desc)
{
    if (nmodparams >= HALSDK_MAX_MODPARAMS) {
        mp_overflow = 1;
        return;
    }
    halsdk_modparam_t *m = &modparams[nmodparams++];
    m->name = name;
    m->kind = kind;
    m->addr = addr;
    m->count = count;
    m->desc = desc;
}

int rtapi_app_main(void);
void rtapi_app_exit(void) __attribute__((weak));

/* rtapi_app_exit() undoes a successful rtapi_app_main() only: as in the
   reference, a module whose rtapi_app_main() failed is dropped without
   it (its exit code may use state that was never made) */
static int started;

static PyObject *scalar_value(char kind, void *addr)
{
    switch (kind) {
    case 'i': case 'I':
        return PyLong_FromLong(*(int *)addr);
    case 'l': case 'L':
        return PyLong_FromLong(*(long *)addr);
    default: {
        const char *s = *(char **)addr;
        return PyUnicode_FromString(s ? s : "");
    }
    }
}

static PyObject *current_value(halsdk_modparam_t *m)
{
    if (m->kind == 'i' || m->kind == 'l' || m->kind == 's')
        return scalar_value(m->kind, m->addr);
    PyObject *list = PyList_New(0);
    size_t step = m->kind == 'I' ? sizeof(int)
                  : m->kind == 'L' ? sizeof(long) : sizeof(char *);
    for (int k = 0; list && k < m->count; k++) {
        char *a = (char *)m->addr + k * step;
        if (m->kind == 'S' && !*(char **)a)
            break;
        PyObject *v = scalar_value(m->kind, a);
        if (!v || PyList_Append(list, v) < 0) {
            Py_XDECREF(v);
            Py_DECREF(list);
            return NULL;
        }
        Py_DECREF(v);
    }
    return list;
}

static int set_scalar(halsdk_modparam_t *m, char kind, void *addr,
                      PyObject *v)
{
    if (kind == 's' || kind == 'S') {
        const char *s = PyUnicode_AsUTF8(v);
        if (!s)
            return -1;
        char *copy = strdup(s);     /* lives as long as the module */
        if (!copy) {
            PyErr_NoMemory();
            return -1;
        }
        *(char **)addr = copy;
        return 0;
    }
    long x = PyLong_AsLong(v);
    if (x == -1 && PyErr_Occurred())
        return -1;
    if ((kind == 'i' || kind == 'I') && (x < INT_MIN || x > INT_MAX)) {
        PyErr_Format(PyExc_ValueError, "parameter %s=%ld is out of range "
                     "for int", m->name, x);
        return -1;
    }
    if (kind == 'i' || kind == 'I')
        *(int *)addr = (int)x;
    else
        *(long *)addr = x;
    return 0;
}

static int set_param(halsdk_modparam_t *m, PyObject *v)
{
    if (m->kind == 'i' || m->kind == 'l' || m->kind == 's')
        return set_scalar(m, m->kind, m->addr, v);
    PyObject *seq = PySequence_Fast(v, "array parameters take a list");
    if (!seq)
        return -1;
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    if (n > m->count) {
        /* the load line's words, as the reference quotes them */
        PyObject *comma = PyUnicode_FromString(",");
        PyObject *strs = PyList_New(0);
        for (Py_ssize_t k = 0; strs && k < n; k++) {
            PyObject *w = PyObject_Str(PySequence_Fast_GET_ITEM(seq, k));
            if (!w || PyList_Append(strs, w) < 0)
                Py_CLEAR(strs);
            Py_XDECREF(w);
        }
        PyObject *text = comma && strs ? PyUnicode_Join(comma, strs) : NULL;
        if (text)
            PyErr_Format(PyExc_ValueError, "%s=%U: can only take %d "
                         "arguments", m->name, text, m->count);
        Py_XDECREF(text);
        Py_XDECREF(strs);
        Py_XDECREF(comma);
        Py_DECREF(seq);
        return -1;
    }
    size_t step = m->kind == 'I' ? sizeof(int)
                  : m->kind == 'L' ? sizeof(long) : sizeof(char *);
    for (Py_ssize_t k = 0; k < n; k++) {
        if (set_scalar(m, m->kind, (char *)m->addr + k * step,
                       PySequence_Fast_GET_ITEM(seq, k)) < 0) {
            Py_DECREF(seq);
            return -1;
        }
    }
    Py_DECREF(seq);
    return 0;
}

/* the halsdk.core.errors class that fits the errno rtapi_app_main returned */
static const char *error_class(int r)
{
    switch (r < 0 ? -r : r) {
    case EINVAL: case ERANGE: case E2BIG:
        return "InvalidError";
    case EEXIST: case EBUSY:
        return "ExistsError";
    case ENOMEM: case ENOSPC:
        return "CapacityError";
    case ENOENT: case ENODEV:
        return "NotFoundError";
    case EPERM: case EACCES:
        return "NotPermittedError";
    default:
        return "LoadError";
    }
}

/* raise the error of a failed rtapi_app_main(): the messages the module
   printed and the HAL's own error, in the class its errno stands for */
static void setup_failed(int r, const char *msgs, const char *hal_error)
{
    char text[4096 + 600];
    size_t n = 0;
    text[0] = 0;
    /* the messages, one line each, joined with "; " */
    for (const char *p = msgs; *p && n < sizeof(text) - 3; ) {
        size_t len = strcspn(p, "\n");
        if (len) {
            int w = snprintf(text + n, sizeof(text) - n, "%s%.*s",
                             n ? "; " : "", (int)len, p);
            n += w > 0 ? (size_t)w : 0;
        }
        p += len + (p[len] == '\n');
    }
    if (n >= sizeof(text))
        n = sizeof(text) - 1;
    if (hal_error && *hal_error && !strstr(text, hal_error))
        n += snprintf(text + n, sizeof(text) - n, "%s%s", n ? "; " : "",
                      hal_error);
    if (!n)
        snprintf(text, sizeof(text), "rtapi_app_main() returned %d (%s)",
                 r, strerror(r < 0 ? -r : r));
    PyObject *errors = PyImport_ImportModule("halsdk.core.errors");
    PyObject *cls = errors ? PyObject_GetAttrString(errors, error_class(r))
                           : NULL;
    Py_XDECREF(errors);
    if (!cls)
        return;
    /* the value itself too: a userspace program's exit status */
    PyObject *exc = PyObject_CallFunction(cls, "s", text);
    Py_DECREF(cls);
    PyObject *status = exc ? PyLong_FromLong(r) : NULL;
    if (status && PyObject_SetAttrString(exc, "status", status) == 0)
        PyErr_SetObject((PyObject *)Py_TYPE(exc), exc);
    Py_XDECREF(status);
    Py_XDECREF(exc);
}

static PyObject *mod_setup(PyObject *self, PyObject *args, PyObject *kw)
{
    if (PyTuple_GET_SIZE(args)) {
        PyErr_SetString(PyExc_TypeError, "setup() takes parameters by "
                        "keyword only");
        return NULL;
    }
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    restore_defaults();
    while (kw && PyDict_Next(kw, &pos, &key, &value)) {
        const char *k = PyUnicode_AsUTF8(key);
        halsdk_modparam_t *m = NULL;
        for (int i = 0; k && i < nmodparams; i++)
            if (strcmp(modparams[i].name, k) == 0)
                m = &modparams[i];
        if (!m) {
            PyErr_Format(PyExc_ValueError, "%s has no parameter '%s'",
                         STR_(HALSDK_MODULE_NAME), k ? k : "?");
            return NULL;
        }
        if (set_param(m, value) < 0)
            return NULL;
    }
    int r;
#ifdef ULAPI
    /* a userspace program runs its whole life in here: its messages go
       out as it prints them */
    const char *msgs = "";
    Py_BEGIN_ALLOW_THREADS
    halsdk_api_ptr->msg_capture(1);     /* clears the last HAL error */
    halsdk_api_ptr->msg_capture(0);
    r = rtapi_app_main();
    Py_END_ALLOW_THREADS
#else
    Py_BEGIN_ALLOW_THREADS
    halsdk_api_ptr->msg_capture(1);
    r = export_symbols();
    if (r == 0) {
        r = rtapi_app_main();
        if (r != 0)
            halsdk_api_ptr->symbol_drop(halsdk_module_name);
    }
    halsdk_api_ptr->msg_capture(0);
    Py_END_ALLOW_THREADS
    const char *msgs = halsdk_api_ptr->captured_msgs();
    if (r == 0)
        fputs(msgs, stderr);
#endif
    started = r == 0;
    if (r == 0)
        Py_RETURN_NONE;
    setup_failed(r, msgs, halsdk_api_ptr->last_error());
    return NULL;
}

/* newinst COMP NAME [arg=TEXT]: the constructor the module set with
   hal_set_constructor() makes the instance NAME */
static PyObject *mod_new_instance(PyObject *self, PyObject *args,
                                  PyObject *kw)
{
    const char *name, *arg = "";
    static char *kwlist[] = {"name", "arg", NULL};
    if (!PyArg_ParseTupleAndKeywords(args, kw, "s|s:new_instance", kwlist,
                                     &name, &arg))
        return NULL;
    if (!make_instance) {
        PyObject *errors = PyImport_ImportModule("halsdk.core.errors");
        PyObject *cls = errors ? PyObject_GetAttrString(errors,
                                                        "NotPermittedError")
                               : NULL;
        Py_XDECREF(errors);
        if (cls) {
            PyErr_Format(cls, "component '%s' does not support instances "
                         "(newinst): it set no constructor",
                         STR_(HALSDK_MODULE_NAME));
            Py_DECREF(cls);
        }
        return NULL;
    }
    char *prefix = strdup(name), *text = strdup(arg);
    if (!prefix || !text) {
        free(prefix);
        free(text);
        return PyErr_NoMemory();
    }
    int r;
    Py_BEGIN_ALLOW_THREADS
    halsdk_api_ptr->msg_capture(1);
    /* the new pins belong to the component, which takes them while it
       is not ready */
    r = halsdk_api_ptr->comp_unready(make_comp);
    if (r == 0) {
        r = make_instance(prefix, text);
        halsdk_api_ptr->comp_ready(make_comp);
    }
    halsdk_api_ptr->msg_capture(0);
    Py_END_ALLOW_THREADS
    free(prefix);
    free(text);
    const char *msgs = halsdk_api_ptr->captured_msgs();
    if (r == 0) {
        fputs(msgs, stderr);
        Py_RETURN_NONE;
    }
    setup_failed(r, msgs, halsdk_api_ptr->last_error());
    return NULL;
}

static PyObject *mod_cleanup(PyObject *self, PyObject *unused)
{
    if (rtapi_app_exit && started) {
        started = 0;
        Py_BEGIN_ALLOW_THREADS
        rtapi_app_exit();
        Py_END_ALLOW_THREADS
    }
    halsdk_api_ptr->symbol_drop(halsdk_module_name);
    Py_RETURN_NONE;
}

static PyMethodDef methods[] = {
    {"setup", (PyCFunction)(void (*)(void))mod_setup,
     METH_VARARGS | METH_KEYWORDS,
     "Set module parameters and run rtapi_app_main()."},
    {"cleanup", mod_cleanup, METH_NOARGS, "Run rtapi_app_exit()."},
    {"new_instance", (PyCFunction)(void (*)(void))mod_new_instance,
     METH_VARARGS | METH_KEYWORDS,
     "Make an instance with the hal_set_constructor() function."},
    {NULL, NULL, 0, NULL}
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, STR_(HALSDK_MODULE_NAME),
    "HAL component written in C", -1, methods,
    NULL, NULL, NULL, NULL
};

PyMODINIT_FUNC CAT_(PyInit_, HALSDK_MODULE_NAME)(void)
{
    if (import_halsdk() < 0)
        return NULL;
    if (export_overflow) {
        PyErr_Format(PyExc_ImportError, "%s exports more than %d symbols",
                     STR_(HALSDK_MODULE_NAME), MAX_EXPORTS);
        return NULL;
    }
    if (mp_overflow) {
        PyErr_Format(PyExc_ImportError, "%s declares more than %d module "
                     "parameters", STR_(HALSDK_MODULE_NAME),
                     HALSDK_MAX_MODPARAMS);
        return NULL;
    }
    if (save_defaults() < 0)
        return PyErr_NoMemory();
    PyObject *m = PyModule_Create(&module);
    if (!m)
        return NULL;
    PyObject *mp = PyDict_New();
    for (int i = 0; mp && i < nmodparams; i++) {
        halsdk_modparam_t *p = &modparams[i];
        PyObject *cur = current_value(p);
        PyObject *t = cur ? Py_BuildValue("(C N s)", p->kind, cur,
                                          p->desc ? p->desc : "") : NULL;
        if (!t || PyDict_SetItemString(mp, p->name, t) < 0) {
            Py_XDECREF(t);
            Py_CLEAR(mp);
            break;
        }
        Py_DECREF(t);
    }
    if (!mp || PyModule_AddObject(m, "modparams", mp) < 0) {
        Py_XDECREF(mp);
        Py_DECREF(m);
        return NULL;
    }
    /* newinst's one parameter: the constructor's argument */
    PyObject *ip = Py_BuildValue("{s:(C s s)}", "arg", 's', "",
                                 "the argument of the constructor");
    if (!ip || PyModule_AddObject(m, "instance_params", ip) < 0) {
        Py_XDECREF(ip);
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
