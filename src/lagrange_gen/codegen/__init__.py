"""Code generation stage: Dynamics -> KernelSpecs -> text -> generated/<name>.py."""

from .generate import generate_model, generate_text, output_path
from ..keys import read_key
from .spec import KernelSpec, make_kernels

__all__ = ["generate_model", "generate_text", "output_path", "read_key", "KernelSpec", "make_kernels"]
