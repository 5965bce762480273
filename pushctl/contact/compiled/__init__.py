"""The contact engine's compiled kernels (numba, cached on disk): the step's small dense
algebra, its MLCP assembly and solves, the refinement of the ground's friction boxes, the
step end and the friction field's arithmetic. Their contracts: README.md beside this file."""
