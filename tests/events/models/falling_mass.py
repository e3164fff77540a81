"""A mass falling from height y0 under gravity g hits the ground y = 0 at sqrt(2 y0 / g) with
speed -sqrt(2 g y0); the terminal event ``ground`` stops the run there."""

from lagrange_gen import Event, Model, coordinates, parameters

y = coordinates("y")
m, g = parameters("m g", defaults=(1.0, 9.81))

model = Model("falling_mass", [y], T=m * y.d**2 / 2, V=m * g * y,
              events={"ground": Event(y, terminal=True, direction=-1),
                      "half_way": Event(y - 1.0, direction=-1)})
