# Declarations of the HAL and RTAPI C API for components written in Cython.
#
#     from halsdk cimport hal
#     hal.import_halsdk()          # once, at module level
#
# Pins are pointers into shared memory: read and write them as d.out[0].
# Realtime functions have the signature
#     cdef void f(void *arg, long period) noexcept nogil

cdef extern from "halsdk_api.h":
    int import_halsdk() except -1

cdef extern from "hal.h" nogil:
    enum:
        HAL_NAME_LEN
        HAL_LOCK_NONE, HAL_LOCK_LOAD, HAL_LOCK_CONFIG, HAL_LOCK_PARAMS
        HAL_LOCK_RUN, HAL_LOCK_ALL

    ctypedef bint hal_bit_t
    ctypedef double hal_float_t
    ctypedef int hal_s32_t
    ctypedef unsigned int hal_u32_t
    ctypedef long long hal_s64_t
    ctypedef unsigned long long hal_u64_t
    ctypedef double real_t

    ctypedef enum hal_type_t:
        HAL_BIT, HAL_FLOAT, HAL_S32, HAL_U32, HAL_S64, HAL_U64
    ctypedef enum hal_pin_dir_t:
        HAL_IN, HAL_OUT, HAL_IO
    ctypedef enum hal_param_dir_t:
        HAL_RO, HAL_RW

    # a realtime function; the C name is the API header's typedef
    ctypedef void (*hal_funct_t "halsdk_funct_t")(void *arg, long period) \
        noexcept nogil

    int hal_init(const char *name)
    int hal_exit(int comp_id)
    int hal_ready(int comp_id)
    int hal_unready(int comp_id)
    void *hal_malloc(long size)

    int hal_pin_new(const char *name, hal_type_t type, hal_pin_dir_t dir,
                    void **data_ptr_addr, int comp_id)
    int hal_pin_bit_new(const char *name, hal_pin_dir_t dir,
                        hal_bit_t **data_ptr_addr, int comp_id)
    int hal_pin_float_new(const char *name, hal_pin_dir_t dir,
                          hal_float_t **data_ptr_addr, int comp_id)
    int hal_pin_s32_new(const char *name, hal_pin_dir_t dir,
                        hal_s32_t **data_ptr_addr, int comp_id)
    int hal_pin_u32_new(const char *name, hal_pin_dir_t dir,
                        hal_u32_t **data_ptr_addr, int comp_id)
    int hal_pin_s64_new(const char *name, hal_pin_dir_t dir,
                        hal_s64_t **data_ptr_addr, int comp_id)
    int hal_pin_u64_new(const char *name, hal_pin_dir_t dir,
                        hal_u64_t **data_ptr_addr, int comp_id)
    int hal_pin_bit_newf(hal_pin_dir_t dir, hal_bit_t **data_ptr_addr,
                         int comp_id, const char *fmt, ...)
    int hal_pin_float_newf(hal_pin_dir_t dir, hal_float_t **data_ptr_addr,
                           int comp_id, const char *fmt, ...)
    int hal_pin_s32_newf(hal_pin_dir_t dir, hal_s32_t **data_ptr_addr,
                         int comp_id, const char *fmt, ...)
    int hal_pin_u32_newf(hal_pin_dir_t dir, hal_u32_t **data_ptr_addr,
                         int comp_id, const char *fmt, ...)
    int hal_pin_s64_newf(hal_pin_dir_t dir, hal_s64_t **data_ptr_addr,
                         int comp_id, const char *fmt, ...)
    int hal_pin_u64_newf(hal_pin_dir_t dir, hal_u64_t **data_ptr_addr,
                         int comp_id, const char *fmt, ...)

    int hal_param_new(const char *name, hal_type_t type,
                      hal_param_dir_t dir, void *data_addr, int comp_id)
    int hal_param_bit_newf(hal_param_dir_t dir, hal_bit_t *data_addr,
                           int comp_id, const char *fmt, ...)
    int hal_param_float_newf(hal_param_dir_t dir, hal_float_t *data_addr,
                             int comp_id, const char *fmt, ...)
    int hal_param_s32_newf(hal_param_dir_t dir, hal_s32_t *data_addr,
                           int comp_id, const char *fmt, ...)
    int hal_param_u32_newf(hal_param_dir_t dir, hal_u32_t *data_addr,
                           int comp_id, const char *fmt, ...)
    int hal_param_s64_newf(hal_param_dir_t dir, hal_s64_t *data_addr,
                           int comp_id, const char *fmt, ...)
    int hal_param_u64_newf(hal_param_dir_t dir, hal_u64_t *data_addr,
                           int comp_id, const char *fmt, ...)

    int hal_pin_alias(const char *pin_name, const char *alias)
    int hal_param_alias(const char *param_name, const char *alias)

    int hal_signal_new(const char *name, hal_type_t type)
    int hal_signal_delete(const char *name)
    int hal_link(const char *pin_name, const char *sig_name)
    int hal_unlink(const char *pin_name)

    int hal_export_funct(const char *name, hal_funct_t funct, void *arg,
                         int uses_fp, int reentrant, int comp_id)
    int hal_export_functf(hal_funct_t funct, void *arg, int uses_fp,
                          int reentrant, int comp_id, const char *fmt, ...)
    int hal_create_thread(const char *name, unsigned long period_nsec,
                          int uses_fp)
    int hal_thread_delete(const char *name)
    int hal_add_funct_to_thread(const char *funct_name,
                                const char *thread_name, int position)
    int hal_del_funct_from_thread(const char *funct_name,
                                  const char *thread_name)
    int hal_set_lock(unsigned char lock_type)
    unsigned char hal_get_lock()

    # halsdk additions
    int halsdk_inst_new(const char *name, int comp_id)
    const char *halsdk_last_error()

    # streams (halsdk): realtime-safe FIFOs of records
    ctypedef union halsdk_value_t:
        unsigned char b
        int s
        unsigned int u
        double f
        long long ls
        unsigned long long lu
    ctypedef long long halsdk_stream_t
    enum:
        HALSDK_STREAM_MAX_ELEMS
    halsdk_stream_t halsdk_stream_create(const char *name, int owner_id,
                                         int depth, const char *typestring)
    halsdk_stream_t halsdk_stream_attach(const char *name)
    int halsdk_stream_write(halsdk_stream_t s, const halsdk_value_t *rec)
    int halsdk_stream_read(halsdk_stream_t s, halsdk_value_t *rec,
                           unsigned long long *sampleno)
    int halsdk_stream_depth(halsdk_stream_t s)
    int halsdk_stream_maxdepth(halsdk_stream_t s)
    long long halsdk_stream_num_overruns(halsdk_stream_t s)
    long long halsdk_stream_num_underruns(halsdk_stream_t s)
    int halsdk_stream_nelem(halsdk_stream_t s)
    int halsdk_stream_elem_type(halsdk_stream_t s, int index)

cdef extern from "rtapi.h" nogil:
    ctypedef enum msg_level_t:
        RTAPI_MSG_NONE, RTAPI_MSG_ERR, RTAPI_MSG_WARN, RTAPI_MSG_INFO
        RTAPI_MSG_DBG, RTAPI_MSG_ALL
    void rtapi_print_msg(msg_level_t level, const char *fmt, ...)
    void rtapi_print(const char *fmt, ...)
    long long rtapi_get_time()
    long long rtapi_get_clocks()
    int rtapi_set_msg_level(int level)
    int rtapi_get_msg_level()
