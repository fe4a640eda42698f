# the [PYTHON] plugin of the glog programs: globals the ;py, lines see
base = 10
count = 0
