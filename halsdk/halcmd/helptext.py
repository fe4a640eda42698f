"""Short help texts of the halcmd commands (``help`` and ``help CMD``)."""

from __future__ import annotations

HELP: dict[str, str] = {
    "addf": "addf FUNCT THREAD [POSITION]: run FUNCT in THREAD (position 1 "
            "is first, -1 last)",
    "alias": "alias pin|param NAME ALIAS: give a pin or param a second name",
    "delf": "delf FUNCT THREAD: stop running FUNCT in THREAD",
    "delinst": "delinst NAME: remove an instance made by newinst",
    "delsig": "delsig NAME|all: delete a signal, unlinking its pins",
    "debug": "debug LEVEL: set the message level (0 none ... 5 all)",
    "echo": "echo: print each command before it runs",
    "exit": "exit: stop reading commands",
    "getp": "getp NAME: print the value of a param or pin",
    "gets": "gets NAME: print the value of a signal",
    "help": "help [COMMAND]: list the commands or explain one",
    "linkpp": "linkpp PIN1 [ARROW] PIN2: link two pins with a signal named "
              "like PIN1 (use net)",
    "linkps": "linkps PIN [ARROW] SIGNAL: link a pin to a signal (use net)",
    "linksp": "linksp SIGNAL [ARROW] PIN: link a pin to a signal (use net)",
    "list": "list comp|pin|sig|param|funct|thread [PATTERN...]: print names",
    "loadrt": "loadrt COMP [NAME=VALUE...]: load a realtime component",
    "loadusr": "loadusr [-W|-Wn NAME] [-w [-i]] PROGRAM [ARGS]: start a "
               "program (-W: wait until its component is ready, -w: wait "
               "for its exit, -i: ignore its exit status)",
    "lock": "lock [all|tune|none]: forbid changes (tune: loading and "
            "configuration only)",
    "net": "net SIGNAL PIN... : link pins to a signal, creating it if "
           "needed; arrows => <= <=> may stand between the pins",
    "newinst": "newinst COMP NAME [NAME=VALUE...]: make an instance",
    "newsig": "newsig NAME TYPE: create a signal (bit, float, s32, u32, s64, "
              "u64)",
    "print": "print [TEXT]: print a message",
    "ptype": "ptype NAME: print the type of a param or pin",
    "quit": "quit: stop reading commands",
    "save": "save [ITEM] [FILE]: print HAL commands that rebuild the "
            "configuration (comp, alias, sig, sigu, link, linka, net, neta, "
            "netl, netla, param, thread, unconnectedinpins, all, allu)",
    "setexact_for_test_suite_only": "setexact_for_test_suite_only: accepted "
                                    "for compatibility",
    "setp": "setp NAME VALUE (or NAME = VALUE): set a param or an unlinked "
            "input pin",
    "sets": "sets NAME VALUE: set a signal that has no writer",
    "show": "show [ITEM] [PATTERN...]: print items (comp, pin, sig, param, "
            "funct, thread, alias, all)",
    "source": "source FILE: run the commands of a HAL file",
    "start": "start: start the realtime threads",
    "status": "status [lock|mem|all]: print the lock level and memory use",
    "stop": "stop: stop the realtime threads",
    "stype": "stype NAME: print the type of a signal",
    "unalias": "unalias pin|param ALIAS: remove an alias",
    "unecho": "unecho: stop printing commands",
    "unlinkp": "unlinkp PIN: unlink a pin from its signal",
    "unload": "unload COMP|all: remove a component of any kind",
    "unloadrt": "unloadrt COMP|all: unload a realtime component",
    "unloadusr": "unloadusr COMP|all: ask a userspace component to exit",
    "unlock": "unlock [all|tune]: allow changes again",
    "waitusr": "waitusr COMP: wait until a userspace component exits",
}
