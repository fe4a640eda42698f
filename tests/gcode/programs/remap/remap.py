# Python remap procedures (python=, prolog=, epilog=): f(self, **words)


def m401(self, **words):
    # words of the argspec, lower case; G-code run from Python
    p = words.get("p", 0.0)
    self.execute(f"G1 X{p:f} F{20 + words.get('q', 0.0):f}")
    self.params["_m401_level"] = self.remap_level
    return 0


def m403(self, **words):
    return 1 / 0


def m404(self, **words):
    return "m404 fails on purpose"


def m405(self, **words):
    # the block of the remapped code: x_flag, x_number ...
    block = self.blocks[self.remap_level]
    if block.p_flag:
        self.execute(f"G0 Z{block.p_number:f}")
    yield 2  # INTERP_EXECUTE_FINISH: go on at once
    self.execute("G0 Z0")


def prolog420(self, **words):
    self.params["myname"] = 123
    self.params[1] = 345
    return 0


def epilog420(self, **words):
    self.params["_epilog_result"] = self.params["result"]
    self.params["_epilog_value"] = self.return_value
    return 0
