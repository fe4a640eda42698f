"""Userspace components: the generated start-up code and the launcher.

A ``.comp`` with ``option userspace yes`` (or a hand-written C program
built with ``halcompile --compile -u prog.c``) becomes a program that
``loadusr`` starts.  halsdk has no shared C library for its core (the C
API lives in a capsule of the Python extension ``halsdk.core._core``), so the
program is made of two files, both written by ``halcompile --compile``:

``NAME<ext>``
    an extension module built like a realtime C component.  Its
    ``rtapi_app_main`` does what the reference's ``main()`` does: takes
    ``count=``/``names=`` out of the command line, calls
    ``userinit(argc, argv)`` (``option userinit``), creates the component
    (a userspace one: it belongs to the launching process), makes it
    ready and runs ``user_mainloop()``.  Loaded with ``loadrt`` by
    mistake, it refuses to start.
``NAME``
    an executable Python script, the launcher: it attaches to the running
    HAL instance (``$HALSDK_INSTANCE``), imports the module next to it and
    hands it its command line (:func:`run`).  ``loadusr NAME`` finds it
    on ``PATH``; ``halcompile --install`` also writes it to the user's
    ``bin`` folder (``$XDG_BIN_HOME`` or ``~/.local/bin``).

Like the reference's, the program ends on ``SIGTERM`` or ``SIGINT`` (the
default action: the process ends at once, whatever ``user_mainloop`` is
doing); ``halcmd unload NAME`` / ``Hal.unload(NAME)`` send ``SIGTERM``
and then remove the component of the dead process.  When
``user_mainloop`` returns, the component is removed and the program ends
with status 0.

The launcher calls :func:`halsdk.userspace.run`, the runtime that lives in
halsdk: halcompile is needed to build a program, never to run one.
"""

from __future__ import annotations

import os
import stat
import sys

from halsdk.loader import USER_ARGV_PARAM as ARGV_PARAM
from halsdk.userspace import MAX_ARGS


def app_main(w, comp) -> None:   # w: gen_c._Writer, comp: Component
    """Append the start-up code of userspace component ``comp`` to the
    generated C file of ``w``."""
    from halcompile.gen_c import c_string, instance_code

    name = comp.name
    prefix = c_string(comp.prefix)
    personality = comp.has_personality
    singleton = bool(comp.option("singleton"))
    count_function = bool(comp.option("count_function"))
    userinit = bool(comp.option("userinit"))
    cleanup = "extra_cleanup();" if comp.option("extra_cleanup") else ""
    default_count = int(comp.option("default_count", 1))
    w.add(f"static char *{ARGV_PARAM}[{MAX_ARGS}];",
          f"RTAPI_MP_ARRAY_STRING({ARGV_PARAM}, {MAX_ARGS}, "
          "\"command line of a userspace component (set by its "
          "launcher)\");",
          "int argc = 0;", "char **argv = 0;",
          f"static int default_count = {default_count};",
          "static int count = 0;", "static char *names = \"\";",
          "static void user_mainloop(void);")
    if userinit:
        w.add("static void userinit(int argc, char **argv);")
    if personality:
        w.add(f"static int personality_of(const char *inst, int idx) "
              f"{{ (void)inst; (void)idx; return "
              f"{int(comp.option('default_personality', 0))}; }}")

    def export_call(inst: str, idx: str) -> str:
        if personality:
            return f"export({inst}, {idx}, personality_of({inst}, {idx}))"
        return f"export({inst}, {idx})"

    # a singleton or count_function component leaves its command line
    # alone, as the reference's do
    parse = "1" if singleton or count_function else "0"
    w.add("",
          "/* take count=N and names=A,B out of the command line */",
          "static int __comp_user_args(void)", "{",
          "    int found_count = 0, found_names = 0, n = 0;",
          f"    argv = {ARGV_PARAM};",
          "    argc = 0;",
          f"    while (argc < {MAX_ARGS} && argv[argc])",
          "        argc++;",
          "    if (" + parse + ")",
          "        return 0;",
          "    for (int i = 0; i < argc; i++) {",
          "        if (strncmp(argv[i], \"count=\", 6) == 0) {",
          "            count = (int)strtol(argv[i] + 6, NULL, 0);",
          "            found_count = 1;",
          "        } else if (strncmp(argv[i], \"names=\", 6) == 0) {",
          "            names = argv[i] + 6;",
          "            found_names = 1;",
          "        } else {",
          "            argv[n++] = argv[i];",
          "        }",
          "    }",
          "    for (int i = n; i < argc; i++)",
          "        argv[i] = NULL;",
          "    argc = n;",
          "    if (found_count && found_names) {",
          "        rtapi_print_msg(RTAPI_MSG_ERR, \"count= and names= are "
          "mutually exclusive\\n\");",
          "        return -EINVAL;",
          "    }",
          "    return 0;", "}", "",
          "int rtapi_app_main(void)", "{", "    int r = 0;",
          f"    if (!{ARGV_PARAM}[0]) {{",
          "        rtapi_print_msg(RTAPI_MSG_ERR, \"this is a userspace "
          f"component: start it with 'loadusr {name}'\\n\");",
          "        return -ENOEXEC;", "    }",
          "    r = __comp_user_args();", "    if (r != 0)",
          "        return r;")
    if userinit:
        w.add("    userinit(argc, argv);")
    w.add("    __comp_first_inst = __comp_last_inst = NULL;",
          f"    comp_id = hal_init({c_string(name)});",
          "    if (comp_id < 0)", "        return comp_id;")
    w.add(*instance_code(export_call, prefix, singleton=singleton,
                         count_function=count_function, exclusive=False,
                         check_empty=True))
    w.add("    if (r != 0) {")
    if cleanup:
        w.add(f"        {cleanup}")
    w.add("        hal_exit(comp_id);", "        comp_id = -1;",
          "        return r;", "    }",
          "    hal_ready(comp_id);",
          "    user_mainloop();",
          "    return 0;", "}", "",
          "void rtapi_app_exit(void)", "{", "    if (comp_id < 0)",
          "        return;")
    if cleanup:
        w.add(f"    {cleanup}")
    w.add("    hal_exit(comp_id);", "    comp_id = -1;", "}", "")


def program_wrapper() -> str:
    """The C file that turns a hand-written userspace program (built with
    ``-Dmain=halsdk_user_main``) into a component module: its
    ``rtapi_app_main`` calls the program's ``main`` with the command
    line, and returns what it returns."""
    return "\n".join([
        "/* generated by halsdk's halcompile: runs the main() of a "
        "userspace program */",
        '#include "rtapi.h"', '#include "rtapi_app.h"', '#include "hal.h"',
        f"static char *{ARGV_PARAM}[{MAX_ARGS} + 1];",
        f"RTAPI_MP_ARRAY_STRING({ARGV_PARAM}, {MAX_ARGS}, "
        "\"command line (set by the launcher)\");",
        "int main(int argc, char **argv);",
        "int rtapi_app_main(void)", "{", "    int argc = 0;",
        f"    if (!{ARGV_PARAM}[0]) {{",
        "        rtapi_print_msg(RTAPI_MSG_ERR, \"a userspace program: "
        "start it with loadusr\\n\");",
        "        return -22;", "    }",
        f"    while (argc < {MAX_ARGS} && {ARGV_PARAM}[argc])",
        "        argc++;",
        f"    {ARGV_PARAM}[argc] = 0;",
        f"    return main(argc, {ARGV_PARAM});", "}", ""])


# ------------------------------------------------------------ launcher

def launcher_script(name: str, module_path: str) -> str:
    """The text of the executable launcher of component ``name`` whose
    module is at ``module_path`` (looked for next to the script first)."""
    return (f"#!{sys.executable}\n"
            f"# {name}: starts the userspace HAL component {name} "
            "(written by halcompile)\n"
            "import os\nimport sys\n\n"
            "from halsdk.userspace import run\n\n"
            f"MODULE = {os.path.basename(module_path)!r}\n"
            f"INSTALLED = {os.path.abspath(module_path)!r}\n"
            "here = os.path.join(os.path.dirname(os.path.realpath("
            "__file__)), MODULE)\n"
            "sys.exit(run(here if os.path.isfile(here) else INSTALLED, "
            "sys.argv))\n")


def write_launcher(folder: str, name: str, module_path: str) -> str:
    """Write the launcher script ``folder/name`` (mode 755)."""
    os.makedirs(folder, exist_ok=True)
    path = os.path.join(folder, name)
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(launcher_script(name, module_path))
    os.chmod(tmp, os.stat(tmp).st_mode | stat.S_IXUSR | stat.S_IXGRP
             | stat.S_IXOTH | stat.S_IRGRP | stat.S_IROTH)
    os.replace(tmp, path)
    return path


def user_bin_dir() -> str:
    """Where ``halcompile --install`` puts launchers of userspace
    components: ``$XDG_BIN_HOME`` or ``~/.local/bin``."""
    return os.environ.get("XDG_BIN_HOME") or os.path.join(
        os.path.expanduser("~"), ".local", "bin")
