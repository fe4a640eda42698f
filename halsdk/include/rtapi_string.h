/*
 * rtapi_string.h - string functions usable in realtime code: the C
 * library's, and bounded copies that always terminate the result.
 */
#ifndef RTAPI_STRING_H
#define RTAPI_STRING_H

#include <stdlib.h>
#include <string.h>

#include "rtapi.h"
#include "rtapi_gfp.h"

RTAPI_BEGIN_DECLS

#ifdef __cplusplus
#define rtapi_static_assert(cond, msg) static_assert(cond, msg)
#define rtapi_is_array(x) (std::is_array<decltype(x)>::value)
#else
#define rtapi_static_assert(cond, msg) _Static_assert(cond, msg)
/* an array and a pointer to its first element have different types */
#define rtapi_is_array(x)                                                  \
    (!__builtin_types_compatible_p(__typeof__(x), __typeof__(&(x)[0])))
#endif

/* copy src into dst of size bytes, always terminated; the length of src
   (a result >= size means it was cut) */
static inline size_t rtapi_strlcpy(char *dst, const char *src, size_t size)
{
    size_t n = strlen(src);
    if (size) {
        size_t k = n < size - 1 ? n : size - 1;
        memcpy(dst, src, k);
        dst[k] = 0;
    }
    return n;
}

/* append src to the string in dst of size bytes, always terminated */
static inline size_t rtapi_strlcat(char *dst, const char *src, size_t size)
{
    size_t used = strnlen(dst, size);
    if (used == size)
        return size + strlen(src);
    return used + rtapi_strlcpy(dst + used, src, size - used);
}

/* the same into an array, whose size the compiler knows */
#define rtapi_strxcpy(dst, src) ({                                         \
    rtapi_static_assert(rtapi_is_array(dst), "dst must be an array");      \
    rtapi_strlcpy(dst, src, sizeof(dst));                                  \
})
#define rtapi_strxcat(dst, src) ({                                         \
    rtapi_static_assert(rtapi_is_array(dst), "dst must be an array");      \
    rtapi_strlcat(dst, src, sizeof(dst));                                  \
})

#define rtapi_kstrdup(s, gfp) strdup(s)

/* split at blanks into a NULL-terminated, malloc'd array (one block:
   free it with rtapi_argv_free); *argc gets the number of words */
static inline char **rtapi_argv_split(rtapi_gfp_t gfp, const char *str,
                                      int *argc)
{
    size_t len = strlen(str);
    int words = 0;
    (void)gfp;
    for (const char *p = str; *p;) {
        while (*p == ' ' || *p == '\t' || *p == '\n')
            p++;
        if (!*p)
            break;
        words++;
        while (*p && *p != ' ' && *p != '\t' && *p != '\n')
            p++;
    }
    char **argv = (char **)malloc((words + 1) * sizeof(char *) + len + 1);
    if (!argv)
        return NULL;
    char *text = (char *)(argv + words + 1);
    memcpy(text, str, len + 1);
    int n = 0;
    for (char *p = text; *p;) {
        while (*p == ' ' || *p == '\t' || *p == '\n')
            *p++ = 0;
        if (!*p)
            break;
        argv[n++] = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\n')
            p++;
    }
    argv[n] = NULL;
    if (argc)
        *argc = n;
    return argv;
}

static inline void rtapi_argv_free(char **argv)
{
    free(argv);
}

RTAPI_END_DECLS

#endif
