/*
 * hostmot2.c - the module hostmot2, which LinuxCNC configurations load
 * before hm2_eth ("loadrt hostmot2").  In halsdk, hm2_eth holds the whole
 * driver; hostmot2 only takes the reference's modparams (for debugging
 * and smart serial, which halsdk does not support) and makes the
 * component "hostmot2", so those configurations load unchanged.
 */
#include "rtapi.h"
#include "rtapi_app.h"
#include "hal.h"

MODULE_AUTHOR("halsdk");
MODULE_DESCRIPTION("HostMot2 (loaded for compatibility; see hm2_eth)");
MODULE_LICENSE("GPL");

static int debug_idrom = 0;
RTAPI_MP_INT(debug_idrom, "unused (compatibility)");
static int debug_module_descriptors = 0;
RTAPI_MP_INT(debug_module_descriptors, "unused (compatibility)");
static int debug_pin_descriptors = 0;
RTAPI_MP_INT(debug_pin_descriptors, "unused (compatibility)");
static int debug_modules = 0;
RTAPI_MP_INT(debug_modules, "unused (compatibility)");
static int use_serial_numbers = 0;
RTAPI_MP_INT(use_serial_numbers, "unused: smart serial is not supported");
static int sserial_baudrate = -1;
RTAPI_MP_INT(sserial_baudrate, "unused: smart serial is not supported");

static int comp_id;

int rtapi_app_main(void)
{
    comp_id = hal_init("hostmot2");
    if (comp_id < 0)
        return comp_id;
    hal_ready(comp_id);
    return 0;
}

void rtapi_app_exit(void)
{
    hal_exit(comp_id);
}
