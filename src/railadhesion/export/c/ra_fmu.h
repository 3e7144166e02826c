/* railadhesion native FMUs: the interface between the FMI 2.0 layer (ra_fmi2.c) and a model.
 *
 * A model is three records and one compiled step function:
 *
 *   state     what the model carries from step to step, and its outputs;
 *   settings  fixed data: the parameter set, the FMU's parameters;
 *   inputs    what the co-simulation master sets before each step;
 *
 *   int step(void *state, const void *settings, const void *inputs, double dt);
 *
 * step advances *state by dt seconds (dt > 0) with the current inputs, or, for an algebraic
 * model (RA_FEEDTHROUGH 1), computes the outputs of the current inputs (dt is then ignored and
 * may be 0). It returns 0 on success, else a code k > 0 whose message is RA_STEP_ERRORS[k]
 * (outputs are then NaN). It must not allocate, must not keep pointers to the records, and
 * must give the same result for the same records (the FMU's state is the records: saving and
 * restoring it is a memcpy). An optional
 *
 *   int init(void *state, const void *settings, const void *inputs);
 *
 * runs at fmi2ExitInitializationMode (RA_HAS_INIT 1), e.g. to derive the initial state from
 * parameters set by the master.
 *
 * The records are C structs generated from the NumPy structured dtypes the step was compiled
 * for (railadhesion.export.native.c_struct); the generated header ra_model.h checks their
 * layout with _Static_assert, defines their start values, the variable table below and:
 *
 *   RA_MODEL_IDENTIFIER, RA_GUID   strings, as in modelDescription.xml
 *   RA_FEEDTHROUGH, RA_HAS_INIT    0 or 1
 *   RA_STEP, RA_INIT               the compiled functions
 *   RA_N_VARIABLES, RA_VARIABLES   the FMU's Real variables, indexed by value reference
 *   RA_N_STEP_ERRORS, RA_STEP_ERRORS
 */
#ifndef RA_FMU_H
#define RA_FMU_H

#include <stddef.h>
#include <stdint.h>

/* Where a variable lives: */
enum ra_record { RA_STATE = 0, RA_SETTINGS = 1, RA_INPUTS = 2 };
/* FMI causality (inputs live in the inputs record, parameters in settings, outputs in state): */
enum ra_causality { RA_INPUT = 0, RA_PARAMETER = 1, RA_OUTPUT = 2 };
/* C type of the field (fmi2SetReal rounds to the nearest integer, ties to even): */
enum ra_type { RA_F64 = 0, RA_I64 = 1, RA_I32 = 2, RA_U8 = 3 };

typedef struct {
    const char *name;
    int causality;      /* enum ra_causality */
    int record;         /* enum ra_record */
    size_t offset;      /* byte offset of the value in its record */
    int type;           /* enum ra_type */
    double min, max;    /* allowed range of fmi2SetReal (min and max as declared in
                           modelDescription.xml); NaN and infinite values are always refused */
    int min_open;       /* 1: the value must be > min (else >= min) */
} ra_variable;

typedef int (*ra_step_function)(void *state, const void *settings, const void *inputs,
                                double dt);
typedef int (*ra_init_function)(void *state, const void *settings, const void *inputs);

#endif
