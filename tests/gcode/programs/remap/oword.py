# Python o-word subroutines: o<name> call [a] [b] calls name(self, a, b)


def twice(self, *args):
    return 2 * args[0]


def count_args(self, *args):
    return float(len(args))


def nothing(self, *args):
    self.params["_touched"] = sum(args)


def refuse(self, *args):
    return "refused by oword.refuse"


def raises(self, *args):
    values = {}
    return values["missing"]
