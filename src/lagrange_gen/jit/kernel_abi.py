"""What the runtime may assume about a generated kernel's arguments, without loading the
generator (no sympy): codegen.spec shapes the outputs by it, jit.portable types the kernels'
arguments by it."""

#: Output arguments that are 2-D arrays even when they have one column (every other output with
#: one column is a 1-D array).
ALWAYS_2D = frozenset({"H", "J", "Jq", "Jqd", "dJw", "dJTlam", "out_mat", "G", "coef", "Ju", "Cq",
                       "Cqd", "Du", "WN", "WT", "A", "dAw", "dATmu", "dc", "dgamma_dq",
                       "dgamma_dqd", "Jp"})

#: The arguments of every generated kernel, in order: (name, shape), shape None for the scalar
#: time t, else a tuple of dimension names (see kernel_dimensions). What a call from Python is
#: checked against (jit.python_calls): the kernels index their arrays without bounds checks.
ARGUMENTS = {
    "mass_matrix": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("H", ("n", "n"))),
    "dynamics": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                 ("H", ("n", "n")), ("rhs", ("n",))),
    "rhs": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)), ("out", ("n",))),
    "energy": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",))),
    "momentum_rate": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                      ("out", ("n",))),
    "power": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
              ("out", ("power",))),
    "transport": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("out", ("n",))),
    "transport_dq": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("out_mat", ("n", "n"))),
    "rhs_jacobian": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                     ("Jq", ("n", "n")), ("Jqd", ("n", "n"))),
    "momentum_rate_jacobian": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                               ("Jq", ("n", "n")), ("Jqd", ("n", "n"))),
    "mass_matvec_dq": (("q", ("n",)), ("w", ("n",)), ("t", None), ("p", ("n_params",)),
                       ("out_mat", ("n", "n"))),
    "constraints": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                    ("phi", ("m",)), ("J", ("m", "n")), ("gamma", ("m",))),
    "constraint_rate": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("out", ("m",))),
    "constraint_dq": (("q", ("n",)), ("w", ("n",)), ("lam", ("m",)), ("t", None),
                      ("p", ("n_params",)), ("dJw", ("m", "n")), ("dJTlam", ("n", "n"))),
    "elements": (("q", ("n",)), ("p", ("n_params",)), ("s", ("ne",)), ("G", ("ne", "n")),
                 ("coef", ("ne", "three"))),
    "elements_hessian": (("q", ("n",)), ("we", ("ne",)), ("p", ("n_params",)),
                         ("out_mat", ("n", "n"))),
    "events": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
               ("out", ("n_events",))),
    "forward_dynamics": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                         ("H", ("n", "n")), ("qdd", ("n",))),
    "forward_dynamics_jacobian": (("q", ("n",)), ("qd", ("n",)), ("t", None),
                                  ("p", ("n_params",)), ("H", ("n", "n")), ("qdd", ("n",)),
                                  ("Jq", ("n", "n")), ("Jqd", ("n", "n")), ("W", ("n", "n"))),
    "forward_dynamics_torques": (("q", ("n",)), ("qd", ("n",)), ("tau", ("n",)), ("t", None),
                                 ("p", ("n_params",)), ("H", ("n", "n")), ("qdd", ("n",))),
    "inverse_dynamics": (("q", ("n",)), ("qd", ("n",)), ("qdd", ("n",)), ("t", None),
                         ("p", ("n_params",)), ("tau", ("n",))),
    "gravity_forces": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("out", ("n",))),
    "bias_forces": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                    ("out", ("n",))),
    "contacts": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("gap", ("c",)), ("WN", ("c", "n")),
                 ("WT", ("c2", "n")), ("coef", ("c", "two"))),
    "contact_bias": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("out", ("c3",))),
    "contact_rates": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                      ("out", ("c3",))),
    "nonholonomic": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                     ("A", ("r", "n")), ("b", ("r",)), ("gamma", ("r",))),
    "nonholonomic_dq": (("q", ("n",)), ("qd", ("n",)), ("w", ("n",)), ("mu", ("r",)), ("t", None),
                        ("p", ("n_params",)), ("dAw", ("r", "n")), ("dATmu", ("n", "n")),
                        ("dc", ("r", "n")), ("dgamma_dq", ("r", "n")), ("dgamma_dqd", ("r", "n"))),
    "constraint_gamma_dq": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                            ("dgamma_dq", ("m", "n")), ("dgamma_dqd", ("m", "n"))),
    "rhs_dp": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
               ("Jp", ("n", "n_params"))),
    "momentum_rate_dp": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                         ("Jp", ("n", "n_params"))),
    "mass_matvec_dp": (("q", ("n",)), ("w", ("n",)), ("t", None), ("p", ("n_params",)),
                       ("Jp", ("n", "n_params"))),
    "transport_dp": (("q", ("n",)), ("t", None), ("p", ("n_params",)), ("Jp", ("n", "n_params"))),
    "input_jacobian": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                       ("Ju", ("n", "n_inputs"))),
    "outputs": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                ("out", ("n_outputs",))),
    "output_jacobian": (("q", ("n",)), ("qd", ("n",)), ("t", None), ("p", ("n_params",)),
                        ("Cq", ("n_outputs", "n")), ("Cqd", ("n_outputs", "n")),
                        ("Du", ("n_outputs", "n_inputs"))),
}


def kernel_dimensions(namespace):
    """{dimension name: size} of a generated module from its constants (``namespace``: its
    globals): n, m, n_params, ne, n_events, n_inputs, n_outputs, power (2 n + 2: power, the
    work rate and its parts), c (contacts), c2 (2 c: the tangent rows), c3 (3 c: normal, tangent 1
    and tangent 2 rows), r (nonholonomic constraints), two (the columns of a
    contact's coefficients) and three (the columns of an element's coefficients)."""
    n = namespace["N_COORDS"]
    return dict(n=n, m=namespace.get("N_CONSTRAINTS", 0), n_params=namespace["N_PARAMS"],
                ne=namespace.get("N_ELEMENTS", 0), n_events=namespace.get("N_EVENTS", 0),
                n_inputs=namespace.get("N_INPUTS", 0), n_outputs=namespace.get("N_OUTPUTS", 0),
                c=namespace.get("N_CONTACTS", 0), r=namespace.get("N_NONHOLONOMIC", 0),
                c2=2 * namespace.get("N_CONTACTS", 0), c3=3 * namespace.get("N_CONTACTS", 0), power=2 * n + 2, two=2, three=3)


def argument_shapes(kernel, dimensions):
    """[(argument name, shape tuple or None for a scalar)] of ``kernel`` for a module of these
    ``dimensions`` (kernel_dimensions); None for a kernel not in ARGUMENTS."""
    if kernel not in ARGUMENTS:
        return None
    return [(name, None if dims is None else tuple(dimensions[d] for d in dims))
            for name, dims in ARGUMENTS[kernel]]
