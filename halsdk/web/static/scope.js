// The Scope page of the HAL workbench.
"use strict";
