"""Forward sensitivities of the fixed-step methods: the exact derivative of each step
(discretise-then-differentiate), one module per method beside its stepper
(steppers/methods/<method>.py), with the loop and the tangent algebra they share in core.py.

Each module defines
    prepare(kern, q, v, t, p, settings, ws, tw, cols) -> status    the tangent's own state at t0
    step(kern, q0, v0, q, v, t, h, p, settings, ws, tw, cols) -> status
        after the method's step from (q0, v0) at t to (q, v), with its workspace ws holding the
        step's Newton solutions: tw.S (2n, c) <- the tangent at the step's end
    run(kern, q0, v0, t0, h, n_steps, save_every, p, settings, cols, S0, out_q, out_v, out_S,
        out_stats) -> (status, steps done)                       cached, the portable table kern
and run/sensitivities.py calls ``run`` (lagrange_gen.simulate(..., sensitivities=[...])).
"""

#: The methods with forward sensitivities (their modules here).
SENSITIVITY_METHODS = ("explicit_euler", "symplectic_euler", "verlet", "midpoint",
                       "implicit_euler", "rk4")
