// The Latency page of the HAL workbench.
"use strict";
