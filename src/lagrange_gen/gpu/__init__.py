"""Ensembles on a CUDA GPU: ``lagrange_gen.ensemble(..., device="cuda")``.

One GPU thread runs one member. Nothing here is specific to a model or a method: the member
function (member_source.py) is source text rendered for a generated module and a method, which
calls the CPU stepper library's own functions (the method's ``prepare`` and ``step``,
``run_loop.steps``, ``output.save_row``, ``state_checks.check_state``) and the generated
kernels; numba-cuda compiles all of them as CUDA device functions from the same Python
functions the CPU glue compiles (the generator emits nothing GPU-specific). Workspaces are
per-thread local arrays with the shapes the method's CPU ``workspace`` allocates.

- cuda_runtime.py: importing numba-cuda only when asked, and the one-line refusals (numba-cuda
  missing, no driver, no GPU);
- member_source.py: which methods and models the GPU path runs, the source text of the member
  function and of the kernel that launches one member per thread;
- kernels.py: that text compiled for the GPU (or for numba's CUDA simulator), memoized;
- launch.py: the device arrays, the launch, the copy back into the ensemble's output arrays;
- lowering.py: a check that the CUDA target types and lowers a member without a GPU.

Under numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1) the kernel runs in Python and the member
function is compiled by numba for the CPU (the simulator runs Python, and numba cannot call the
stepper library with a module argument from Python); lowering.py is what checks the CUDA
compile of the same text.

Imports: steppers, jit, errors (and numba-cuda inside functions); run/ reaches it only inside
ensemble(device="cuda"), so nothing here loads for a CPU run.
"""
