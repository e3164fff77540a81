"""What the runtime may assume about a generated kernel's arguments, without loading the
generator (no sympy): codegen.spec shapes the outputs by it, jit.portable types the kernels'
arguments by it."""

#: Output arguments that are 2-D arrays even when they have one column (every other output with
#: one column is a 1-D array).
ALWAYS_2D = frozenset({"H", "J", "Jq", "Jqd", "dJw", "dJTlam", "out_mat", "G", "coef", "Ju", "Cq",
                       "Cqd", "Du", "WN", "WT", "A"})
