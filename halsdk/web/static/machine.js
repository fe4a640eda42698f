// The Machine page of the HAL workbench.
"use strict";
