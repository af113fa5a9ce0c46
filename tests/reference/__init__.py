"""Test oracles: numpy formulations of what the compiled kernels compute, each written
independently of its kernel (vectorised where the kernel loops), against which the tests
compare the kernels to the last bit. Nothing in om_redundant imports them."""
