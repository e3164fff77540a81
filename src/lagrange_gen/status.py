"""Status codes returned by jitted kernels and steppers (turned into exceptions by simulate)."""

OK = 0
SINGULAR_MASS = 1
NEWTON_DIVERGED = 2
NON_FINITE = 3
UNSTABLE = 4      # state grew past the blow-up bound (e.g. Verlet at h*omega > 2)

NAMES = {OK: "ok", SINGULAR_MASS: "singular mass matrix", NEWTON_DIVERGED: "Newton did not converge",
         NON_FINITE: "non-finite state", UNSTABLE: "unstable (state grew past the blow-up bound)"}
