"""Integration: the compiled DOP853 stepper and its validated driver."""

from rollingtop.integrate.driver import IntegrationResult, compile_kernels, integrate

__all__ = ["IntegrationResult", "compile_kernels", "integrate"]
