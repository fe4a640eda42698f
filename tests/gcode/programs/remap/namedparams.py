# Python predefined named parameters: #<_name> reads _name(self)


def _half_pi(self):
    return 1.5707963


def _next_coord_system(self):
    return self.params[5220] + 1.0


def _refused(self):
    return "no value for #<_refused>"


def not_global(self):
    # no leading underscore: not a parameter
    return 1.0
