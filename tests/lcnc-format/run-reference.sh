#!/bin/bash
# run-reference.sh — run the test folders of tests/lcnc-format against the
# reference (LinuxCNC 2.9's halrun, halcmd, halsampler, python3 hal module)
# and judge each with its own checkresult or expected, as `halsdk runtests`
# judges our run.  It re-checks the claim that every folder gives the
# same result with the reference as with halsdk.  Not run in CI (the
# reference is not installed there).
#
#   tests/lcnc-format/run-reference.sh [-r] [-v] [DIR...]
#
#   DIR   test folders or folders holding them (default: every folder
#         beside this script)
#   -r    record: write the reference's result as the folder's `expected`
#         (for a folder that has an `expected`, has no checkresult, or whose
#         checkresult reads `expected`); review the diff before committing
#   -v    show the result and stderr of the tests that failed
#
# The reference is ../shared/tools/reference beside the checkout, or
# $REFERENCE.  It runs as another user in a private copy of the folder,
# one test at a time: the reference has one realtime session per machine,
# so runs hold the lock /tmp/halsdk-reference.lock and wait until the
# previous session's rtapi_app has gone.
set -u
here=$(cd "$(dirname "$0")" && pwd)
top=$(cd "$here/../.." && pwd)
REFERENCE=${REFERENCE:-$top/../shared/tools/reference}
if ! [ -x "$REFERENCE" ]; then
    echo "run-reference.sh: the reference tool was not found (set REFERENCE)" >&2
    exit 2
fi
RECORD=0
VERBOSE=0
while getopts rvh opt; do
    case $opt in
        r) RECORD=1 ;;
        v) VERBOSE=1 ;;
        *) sed -n 2,24p "$0"; exit 2 ;;
    esac
done
shift $((OPTIND-1))
[ $# -gt 0 ] || set -- "$here"

# the reference's own programs, not ours: a plain PATH, no PYTHONPATH
refenv=(env -u PYTHONPATH -u HALSDK_INSTANCE PATH=/usr/local/bin:/usr/bin:/bin)

# under the lock, wait for the end of an earlier session (ours or another
# user's) before starting one
waited='for _ in $(seq 100); do pgrep -x rtapi_app > /dev/null || break; sleep 0.1; done; exec "$@"'

NUM=0; FAIL=0; XFAIL=0; SKIP=0; FAILED=
work=$(mktemp -d /tmp/run-reference.XXXXXX)
trap 'rm -rf "$work"' EXIT
for test in $(find "$@" -type f \( -name test.hal -o -name test.sh -o -name test \) | sort); do
    dir=$(dirname "$test")
    name=$(basename "$test")
    if [ -e "$dir/skip" ]; then
        if ! [ -x "$dir/skip" ] || (cd "$dir" && ./skip > /dev/null); then
            echo "Skipping disabled test: $dir" >&2
            SKIP=$((SKIP+1))
            continue
        fi
    fi
    NUM=$((NUM+1))
    echo "Running test: $dir" >&2
    rm -rf "$work/t"; mkdir "$work/t"
    cp -a "$dir/." "$work/t/"
    rm -f "$work/t/result" "$work/t/stderr"
    case $name in
        test.hal) cmd=(halrun -f test.hal) ;;
        test.sh) cmd=(bash -x test.sh) ;;
        *) cmd=(./test) ;;
    esac
    (cd "$work/t" && flock /tmp/halsdk-reference.lock bash -c "$waited" _ \
        "${refenv[@]}" timeout --foreground 300 "$REFERENCE" "${cmd[@]}" \
        > result 2> stderr)
    rc=$?
    if [ $rc -ne 0 ]; then
        ok=1; reason="test run exited with $rc"
    elif [ -e "$work/t/checkresult" ]; then
        (cd "$work/t" && ./checkresult result > checkresult.out 2>&1)
        ok=$?; reason="checkresult exited with $ok"
    elif [ -f "$work/t/expected" ]; then
        cmp -s "$work/t/expected" "$work/t/result"
        ok=$?; reason="result differed from expected"
    else
        ok=1; reason="Neither expected nor checkresult existed"
    fi
    if [ $RECORD -eq 1 ] && [ $rc -eq 0 ]; then
        if [ -f "$dir/expected" ] || ! [ -e "$dir/checkresult" ] || \
                grep -q expected "$dir/checkresult"; then
            cp "$work/t/result" "$dir/expected"
            echo "recorded $dir/expected" >&2
        fi
    fi
    if [ $ok -ne 0 ]; then
        if [ -e "$dir/xfail" ]; then
            XFAIL=$((XFAIL+1))
            echo "*** $dir: XFAIL: $reason"
        else
            FAIL=$((FAIL+1)); FAILED="$FAILED $dir"
            echo "*** $dir: FAIL: $reason"
            [ -f "$work/t/checkresult.out" ] && cat "$work/t/checkresult.out"
            if [ -f "$work/t/expected" ] && ! [ -e "$work/t/checkresult" ]; then
                diff -u "$work/t/expected" "$work/t/result"
            fi
            if [ $VERBOSE -eq 1 ]; then
                echo "--- result:"; cat "$work/t/result"
                echo "--- stderr:"; cat "$work/t/stderr"
            fi
        fi
    elif [ -e "$dir/xfail" ]; then
        FAIL=$((FAIL+1)); FAILED="$FAILED $dir"
        echo "*** $dir: XPASS: Passed, but was expected to fail"
    fi
done
echo "Reference: $NUM tests run, $((NUM-FAIL-XFAIL)) successful, $FAIL failed + $XFAIL expected, $SKIP skipped"
if [ $FAIL -ne 0 ]; then
    echo "Failed:$FAILED"
    exit 1
fi
exit 0
