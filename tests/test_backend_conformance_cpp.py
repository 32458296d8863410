"""The backend conformance suite on Brian2's C++ standalone target (a build per call): the cases of
``tests/test_backend_conformance.py`` (its ``SEPARATE["cpp"]``) in a file of their own, so that
pytest-xdist runs them on one worker beside the other backends' checks."""

from .test_backend_conformance import SEPARATE, pytest_generate_tests, runs_of, test_conformance

__all__ = ["pytest_generate_tests", "runs_of", "test_conformance"]

SPECS = SEPARATE["cpp"]
