import hal

c = hal.component("writer")
s = hal.stream(c, hal.streamer_base + 1, "bsu")
print(s, s.element_types, s.maxdepth)
for k in range(5):
    try:
        s.write((k % 2 == 0, -k - 1, 3 * k + 1))
    except OSError as e:
        print("record", k, "refused:", e)
    else:
        print("record", k, "written")
print("overruns", s.num_overruns, "writable", s.writable)
