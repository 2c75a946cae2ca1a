#pragma once
// The outputs of igi-solve: see SolvedSceneDocument, SolveReportJson and WriteSolveOutputs in
// solver/solve.h.
#include "solver/solve.h"
