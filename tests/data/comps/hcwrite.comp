component hcwrite "Functions named read and write with a static state struct and an enum";
pin in s32 in_;
pin out s32 out;
pin out s32 stage;
function read nofp;
function write nofp;
option data hcwrite_buf;
license "GPL";
;;
#include <rtapi_string.h>
enum { SLOTS = 3 };
typedef struct { int slot[SLOTS]; int head; } hcwrite_buf;
static int last_written;

static int sum(const hcwrite_buf *b)
{
    int i, s = 0;
    for (i = 0; i < SLOTS; i++)
        s += b->slot[i];
    return s;
}

FUNCTION(read) {
    data.slot[data.head] = in_;
    data.head = (data.head + 1) % SLOTS;
    stage = 1;
}

FUNCTION(write) {
    out = sum(&data);
    last_written = out;
    stage = 2;
}
