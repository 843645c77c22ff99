//! The cosdem master: the Cosserat finite-element macro solver.
