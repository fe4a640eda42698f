component hchomemod "option homemod: a singleton module (a homing-module stand-in)";
pin in float pos;
pin out bit homed;
param rw float switch_at = 2.0;
function _;
option homemod yes;
license "GPL";
;;
homed = pos >= switch_at;
