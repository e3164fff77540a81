"""Fermi-Pasta-Ulam chain of Hairer, Lubich & Wanner (Geometric Numerical Integration, sec. I.5;
HARD_CASES case 5): 2m = 6 unit masses between fixed walls, stiff linear springs of frequency
omega inside each pair (q_{2i-1}, q_{2i}) and soft cubic-force springs (quartic potential)
between the pairs and to the walls, q_0 = q_7 = 0:

    V = omega^2/4 sum_{i=1..3} (q_{2i} - q_{2i-1})^2 + sum_{i=0..3} (q_{2i+1} - q_{2i})^4.

The stiff-spring energies I_j exchange slowly (time scale omega^0) while each stiff spring
oscillates with period 2 pi / omega; see lagrange_gen.bench.hard for the reference values."""
from lagrange_gen import Model, coordinates, parameters

M_PAIRS = 3
qs = coordinates(" ".join(f"q{i}" for i in range(1, 2 * M_PAIRS + 1)))
omega = parameters("omega", defaults=(50.0,))

T = sum(q.d**2 for q in qs) / 2
ends = [0, *qs, 0]                       # q_0 = q_7 = 0: the walls
V = (omega**2 / 4 * sum((ends[2 * i] - ends[2 * i - 1]) ** 2 for i in range(1, M_PAIRS + 1))
     + sum((ends[2 * i + 1] - ends[2 * i]) ** 4 for i in range(0, M_PAIRS + 1)))

model = Model("fpu", coords=qs, T=T, V=V,
              description="Fermi-Pasta-Ulam chain (Hairer-Lubich-Wanner), m = 3 stiff springs.")
