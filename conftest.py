"""Settings for every test path (tests/, and the doctests of robokit/ and course/robocourse/)."""
try:
    from hypothesis import settings
except ImportError:          # the dev extra is not installed: the property tests skip themselves
    settings = None

if settings is not None:
    # Random draws per property test that does not set its own count (the random invalid inputs of
    # tests/test_fuzz_public_api.py, per public function): `make check` passes
    # --hypothesis-profile=check; `make test` and a plain pytest run use "everyday". The fixed invalid
    # cases of every parameter run in both.
    settings.register_profile("check", max_examples=25)
    settings.register_profile("everyday", max_examples=10)
    settings.load_profile("everyday")
