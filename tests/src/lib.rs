//! Integration tests of cosdem live in `tests/tests/`, one file per behaviour.
