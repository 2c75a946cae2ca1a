#pragma once
// The outputs of igi-solve: see SolvedSceneDocument, SolveReportJson and WriteSolveOutputs in
// solver/inverse/solve.h.
#include "solver/inverse/solve.h"
