"""Status codes returned by jitted kernels and steppers (turned into exceptions by simulate)."""

OK = 0
SINGULAR_MASS = 1     # H(q) (or, in a constrained method, J H^-1 J^T) is not positive definite
NEWTON_DIVERGED = 2
NON_FINITE = 3        # NaN/inf in the state, the energy or a Newton matrix
UNSTABLE = 4          # state grew past the blow-up bound (e.g. Verlet at h*omega > 2)
SINGULAR_NEWTON = 5   # a Newton matrix (step Jacobian, KKT matrix) is singular; H may be regular
STEP_TOO_SMALL = 6    # an adaptive step size underflowed the time resolution (0.1 |h| <= |t| eps)
TOO_MANY_STEPS = 7    # an adaptive method attempted settings.max_steps steps in one call
CONTACT_NOT_CONVERGED = 8   # the contact problem of a step: Gauss-Seidel hit its cap, Lemke cycled
CONTACT_NO_SOLUTION = 9     # the contact problem has no solution (Lemke's ray: Painleve's paradox)

NAMES = {OK: "ok", SINGULAR_MASS: "singular mass matrix",
         NEWTON_DIVERGED: "Newton did not converge",
         NON_FINITE: "non-finite state", UNSTABLE: "unstable (state grew past the blow-up bound)",
         SINGULAR_NEWTON: "singular Newton matrix", STEP_TOO_SMALL: "step size too small",
         TOO_MANY_STEPS: "too many steps",
         CONTACT_NOT_CONVERGED: "contact problem did not converge",
         CONTACT_NO_SOLUTION: "contact problem has no solution"}
