/* wheelflat: fmusim built without SUNDIALS CVODE (see tests/fmusim/README.md).
 * Stands in for the Reference-FMUs' FMICVode.c: `--solver cvode` (Model Exchange
 * only) fails with a message; the default `--solver euler` and Co-Simulation are untouched. */
#include <stddef.h>

#include "FMICVode.h"

FMISolver* FMICVodeCreate(const FMISolverParameters* solverFunctions) {
    if (solverFunctions && solverFunctions->logError) {
        solverFunctions->logError("This fmusim was built without CVODE: use --solver euler.\n");
    }
    return NULL;
}

void FMICVodeFree(FMISolver* solver) { (void)solver; }

FMISolverStatus FMICVodeStep(FMISolver* solver, double nextTime, double* timeReached, bool* stateEvent) {
    (void)solver; (void)nextTime; (void)timeReached; (void)stateEvent;
    return FMISolverError;
}

FMISolverStatus FMICVodeReset(FMISolver* solver, double time) {
    (void)solver; (void)time;
    return FMISolverError;
}
