/*
 * loft.c: pde_solve_loft(), solids through sections (pde.h, docs/MATH.md "Lofts").
 *
 * Not built yet: every loft is refused, so that api/ can be written against the interface.
 */
#include "internal.h"

pde_status pde_solve_loft(const pde_loft *loft, const pde_solve_opts *opts, pde_solution **out,
                          pde_diag *diag)
{
    (void)loft, (void)opts, (void)out;
    return pde_fail(diag, PDE_ERR_INVALID, -1, 0, -1, "", "lofts are not solved yet");
}
