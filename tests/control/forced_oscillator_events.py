"""Test model: the forced oscillator (forced_oscillator.py) with an event where x crosses zero,
for the portable controlled glue of a model with events (run_<method>_controlled_events)."""
from lagrange_gen import Model, coordinates, inputs, parameters

x = coordinates("x")
m, k = parameters("m k", defaults=(1.0, 4.0))
u = inputs("u")

model = Model("forced_oscillator_events", coords=[x], T=m * x.d**2 / 2, V=k * x**2 / 2,
              forces={x: u}, inputs=[u], events={"zero": x})
