import sys

print("ARGS", sys.argv[1:], flush=True)
