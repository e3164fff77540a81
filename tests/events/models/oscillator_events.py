"""Linear oscillator m x'' = -k x with events: x(t) = A cos(omega t) from (A, 0) crosses zero at
(j + 1/2) pi / omega (falling for even j), x' at j pi / omega, x = a at acos(a / A) / omega, and
the clock event t = t_mark once."""

from lagrange_gen import Event, Model, coordinates, parameters, t

x = coordinates("x")
m, k, a, t_mark = parameters("m k a t_mark", defaults=(1.0, 4.0, 0.5, 1.234))

model = Model(
    "oscillator_events", [x], T=m * x.d**2 / 2, V=k * x**2 / 2,
    events={
        "zero": x,                                  # both directions
        "up": Event(x, direction=+1),
        "down": Event(x, direction=-1),
        "turn": x.d,
        "level": x - a,                             # a parameter used only here
        "clock": Event(t - t_mark, terminal=False),
    },
    description="linear oscillator with zero-crossing, velocity, level and clock events")
