#pragma once
// What a simulation includes: the Instrument it calls once per timestep, its configuration, the
// zero-copy Field views it hands over and the typed errors. Deliberately light (no OpenCL, no
// full JSON): the stages behind the Instrument (core/, device/, render/, archive/, explore/)
// have headers of their own for code that drives them directly (ARCHITECTURE.md).
#include "insitu/config.hpp"
#include "insitu/error.hpp"
#include "insitu/field.hpp"
#include "insitu/instrument.hpp"
