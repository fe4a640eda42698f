/*
 * capisig.c - a hand-written module that wires itself: it makes signals
 * and links its own pins from C, sets its params by name and checks a
 * set of RTAPI helpers at load time.  Each check that passes sets one
 * bit of the "capisig.checks" pin, so a HAL file can see them.
 */

#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_string.h"
#include "rtapi_math.h"
#include "rtapi_math64.h"
#include "rtapi_mutex.h"
#include "rtapi_bitops.h"
#include "rtapi_list.h"
#include "hal.h"

MODULE_AUTHOR("Example Author");
MODULE_DESCRIPTION("signals and links made from C");
MODULE_LICENSE("GPL");

#define SHM_KEY 0x43415049

static char *signame = "capi-scaled";
RTAPI_MP_STRING(signame, "name of the signal of the output");

typedef struct {
    hal_float_t *in;
    hal_float_t *out;
    hal_u32_t *count;
    hal_u32_t *checks;
    hal_bit_t *shm_ok;
    hal_float_t gain;
    hal_s32_t offset;
    unsigned long lock;
} capisig_t;

typedef struct {
    rtapi_u32 magic;
    rtapi_u32 cycles;
} shared_t;

struct item {
    int value;
    struct rtapi_list_head node;
};

static int comp_id;
static capisig_t *st;
static shared_t *shm;
static int shm_id;

double capisig_scale(double x)
{
    return x * st->gain + st->offset;
}
EXPORT_SYMBOL(capisig_scale);

static void update(void *arg, long period)
{
    capisig_t *s = arg;

    if (rtapi_mutex_try(&s->lock) == 0) {
        *(s->out) = capisig_scale(*(s->in));
        (*(s->count))++;
        rtapi_mutex_give(&s->lock);
    }
    if (shm) {
        shm->cycles++;
        *(s->shm_ok) = shm->magic == 0x1234;
    }
}

static int self_checks(void)
{
    int checks = 0, bit = 0;
    rtapi_s32 off = -1;
    char small[8];
    unsigned long bits[2] = { 0, 0 };
    struct rtapi_list_head head, *pos;
    struct item items[3];
    rtapi_u32 rem;
    void *p1 = 0, *p2 = 0;
    int id2;

    /* 0: the name of our component */
    if (hal_comp_name(comp_id) && strcmp(hal_comp_name(comp_id),
                                         "capisig") == 0)
        checks |= 1 << bit;
    bit++;
    /* 1: a param set by name, 2: a wrong type is refused */
    if (hal_param_float_set("capisig.gain", 2.5) == 0 && st->gain == 2.5)
        checks |= 1 << bit;
    bit++;
    if (hal_param_s32_set("capisig.gain", 3) != 0)
        checks |= 1 << bit;
    bit++;
    /* 3: the generic setter, 4: a missing param is an error */
    if (hal_param_set("capisig.offset", HAL_S32, &off) == 0
        && st->offset == -1)
        checks |= 1 << bit;
    bit++;
    if (hal_param_bit_set("capisig.nosuch", 1) != 0)
        checks |= 1 << bit;
    bit++;
    /* 5: bounded string copies */
    if (rtapi_strxcpy(small, "abcdefghij") == 10
        && strcmp(small, "abcdefg") == 0)
        checks |= 1 << bit;
    bit++;
    /* 6: bit operations */
    set_bit(3, bits);
    set_bit(RTAPI_LONG_BIT + 1, bits);
    if (test_bit(3, bits) && test_and_clear_bit(RTAPI_LONG_BIT + 1, bits)
        && !test_bit(RTAPI_LONG_BIT + 1, bits))
        checks |= 1 << bit;
    bit++;
    /* 7: lists */
    RTAPI_INIT_LIST_HEAD(&head);
    for (int i = 0; i < 3; i++) {
        items[i].value = i + 1;
        rtapi_list_add_tail(&items[i].node, &head);
    }
    int sum = 0, first = 0;
    rtapi_list_for_each(pos, &head) {
        struct item *it = rtapi_list_entry(pos, struct item, node);
        if (!first)
            first = it->value;
        sum += it->value;
    }
    if (sum == 6 && first == 1)
        checks |= 1 << bit;
    bit++;
    /* 8: 64-bit division */
    if (rtapi_div_u64_rem(1000000007ULL, 1000, &rem) == 1000000
        && rem == 7)
        checks |= 1 << bit;
    bit++;
    /* 9: shared memory: a second rtapi_shmem_new of the key is the same
       block */
    id2 = rtapi_shmem_new(SHM_KEY, comp_id, sizeof(shared_t));
    if (id2 > 0 && rtapi_shmem_getptr(shm_id, &p1) == 0
        && rtapi_shmem_getptr(id2, &p2) == 0 && p1 == p2 && p1 == shm)
        checks |= 1 << bit;
    bit++;
    if (id2 > 0)
        rtapi_shmem_delete(id2, comp_id);
    /* 10: a mutex */
    if (rtapi_mutex_try(&st->lock) == 0 && rtapi_mutex_try(&st->lock) != 0)
        checks |= 1 << bit;
    rtapi_mutex_give(&st->lock);
    bit++;
    /* 11: math */
    if (fabs(sin(M_PI / 2) - 1.0) < 1e-12 && RTAPI_INT32_MAX == 2147483647)
        checks |= 1 << bit;
    bit++;
    return checks;
}

int rtapi_app_main(void)
{
    int r;
    void *p;

    comp_id = hal_init("capisig");
    if (comp_id < 0)
        return comp_id;
    st = hal_malloc(sizeof(capisig_t));
    if (!st) {
        hal_exit(comp_id);
        return -ENOMEM;
    }
    if ((r = hal_pin_float_new("capisig.in", HAL_IN, &st->in, comp_id))
        || (r = hal_pin_float_new("capisig.out", HAL_OUT, &st->out,
                                  comp_id))
        || (r = hal_pin_u32_new("capisig.count", HAL_OUT, &st->count,
                                comp_id))
        || (r = hal_pin_u32_new("capisig.checks", HAL_OUT, &st->checks,
                                comp_id))
        || (r = hal_pin_bit_new("capisig.shm-ok", HAL_OUT, &st->shm_ok,
                                comp_id))
        || (r = hal_param_float_new("capisig.gain", HAL_RW, &st->gain,
                                    comp_id))
        || (r = hal_param_s32_new("capisig.offset", HAL_RW, &st->offset,
                                  comp_id))) {
        rtapi_print_msg(RTAPI_MSG_ERR, "CAPISIG: ERROR: pins failed\n");
        hal_exit(comp_id);
        return r;
    }
    st->gain = 1.0;
    st->offset = 0;
    st->lock = 0;

    /* wire the output to a new signal, and the input to another */
    if ((r = hal_signal_new(signame, HAL_FLOAT))
        || (r = hal_link("capisig.out", signame))
        || (r = hal_signal_new("capi-input", HAL_FLOAT))
        || (r = hal_link("capisig.in", "capi-input"))) {
        rtapi_print_msg(RTAPI_MSG_ERR, "CAPISIG: ERROR: wiring failed: "
                        "%d\n", r);
        hal_exit(comp_id);
        return r;
    }

    shm_id = rtapi_shmem_new(SHM_KEY, comp_id, sizeof(shared_t));
    if (shm_id < 0 || rtapi_shmem_getptr(shm_id, &p) < 0) {
        rtapi_print_msg(RTAPI_MSG_ERR, "CAPISIG: ERROR: no shared memory\n");
        hal_exit(comp_id);
        return -ENOMEM;
    }
    shm = p;
    shm->magic = 0x1234;
    shm->cycles = 0;

    *(st->checks) = self_checks();

    r = hal_export_funct("capisig.update", update, st, 1, 0, comp_id);
    if (r) {
        hal_exit(comp_id);
        return r;
    }
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    if (shm_id > 0)
        rtapi_shmem_delete(shm_id, comp_id);
    hal_exit(comp_id);
}
