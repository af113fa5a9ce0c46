"""Python copies of compiled kernels that the tests check the kernels against (oracles only:
the library runs the compiled ones)."""
