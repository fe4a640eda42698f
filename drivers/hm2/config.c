/*
 * config.c - the hostmot2 config string of one board, as hostmot2(9)
 * documents it: blank-separated "key=value" tokens and the flag
 * enable_raw.  Every key of the reference is accepted; the module counts
 * of the modules this driver supports are kept (-1: all the firmware
 * has), the others are read and ignored.  A token the reference does not
 * know is refused.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include "hm2.h"

static int parse_int(const char *s, int *out)
{
    char *end;
    long v;
    if (!*s)
        return -1;
    v = strtol(s, &end, 0);
    if (*end || v < -1 || v > 1000)
        return -1;
    *out = (int)v;
    return 0;
}

/* keys with a number whose module this driver does not support: they
   are accepted, as the reference accepts them, and have no effect */
static const char *const ignored_num[] = {
    "num_dplls", "num_inmuxs", "num_inms", "num_resolvers", "num_3pwmgens",
    "num_oneshots", "num_rcpwmgens", "num_bspis", "num_ssrs", "num_outms",
    "num_xy2mods", "num_periodms", NULL,
};

/* keys with a string value that are accepted and ignored */
static const char *const ignored_str[] = {
    "firmware", "ssi_chan_", "biss_chan_", "fanuc_chan_", "sserial_port_",
    NULL,
};

static int starts(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

int hm2_parse_config(const char *board, const char *text,
                     struct hm2_config *cfg)
{
    char buf[512], *tok, *save = NULL;
    cfg->num_encoders = -1;
    cfg->num_stepgens = -1;
    cfg->num_pwmgens = -1;
    cfg->num_leds = -1;
    cfg->stepgen_width = 2;
    cfg->enable_raw = 0;
    if (text == NULL)
        return 0;
    if (strlen(text) >= sizeof(buf)) {
        rtapi_print_msg(RTAPI_MSG_ERR, "%s: config string too long\n",
                        board);
        return -EINVAL;
    }
    strcpy(buf, text);
    for (tok = strtok_r(buf, " \t\n", &save); tok;
         tok = strtok_r(NULL, " \t\n", &save)) {
        char *eq = strchr(tok, '=');
        const char *val = eq ? eq + 1 : NULL;
        int *dst = NULL, i, known = 0;
        if (strcmp(tok, "enable_raw") == 0) {
            cfg->enable_raw = 1;
            continue;
        }
        if (eq == NULL)
            goto bad;
        *eq = 0;
        if (strcmp(tok, "num_encoders") == 0)
            dst = &cfg->num_encoders;
        else if (strcmp(tok, "num_stepgens") == 0)
            dst = &cfg->num_stepgens;
        else if (strcmp(tok, "num_pwmgens") == 0)
            dst = &cfg->num_pwmgens;
        else if (strcmp(tok, "num_leds") == 0)
            dst = &cfg->num_leds;
        else if (strcmp(tok, "stepgen_width") == 0)
            dst = &cfg->stepgen_width;
        if (dst) {
            if (parse_int(val, dst) < 0) {
                rtapi_print_msg(RTAPI_MSG_ERR, "%s: config: %s=%s is not "
                                "a number (-1 or more)\n", board, tok, val);
                return -EINVAL;
            }
            continue;
        }
        for (i = 0; ignored_num[i]; i++)
            if (strcmp(tok, ignored_num[i]) == 0) {
                int n;
                if (parse_int(val, &n) < 0) {
                    rtapi_print_msg(RTAPI_MSG_ERR, "%s: config: %s=%s is "
                                    "not a number (-1 or more)\n", board,
                                    tok, val);
                    return -EINVAL;
                }
                known = 1;
            }
        for (i = 0; !known && ignored_str[i]; i++)
            if (starts(tok, ignored_str[i]))
                known = 1;
        if (known) {
            if (starts(tok, "sserial_port_") && strspn(val, "xX")
                != strlen(val))
                rtapi_print_msg(RTAPI_MSG_ERR, "%s: config: %s=%s: smart "
                                "serial is not supported by this driver; "
                                "ignored\n", board, tok, val);
            continue;
        }
        *eq = '=';
bad:
        rtapi_print_msg(RTAPI_MSG_ERR, "%s: invalid token in config "
                        "string: \"%s\"\n", board, tok);
        return -EINVAL;
    }
    if (cfg->stepgen_width < 1 || cfg->stepgen_width > 8) {
        rtapi_print_msg(RTAPI_MSG_ERR, "%s: config: stepgen_width=%d is not "
                        "1..8\n", board, cfg->stepgen_width);
        return -EINVAL;
    }
    return 0;
}
