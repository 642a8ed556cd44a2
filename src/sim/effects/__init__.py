"""Effects a scene switches on: each module holds everything one effect is — the check and
normalisation of its keys, the compiled rule the event loop calls, and its observables. An
effect a scene does not use reaches the loop as None, and numba compiles it away."""
