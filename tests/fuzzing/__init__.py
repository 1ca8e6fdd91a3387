"""Generated fuzzing of the files and requests users send (``tests/test_fuzz.py`` runs a fast
profile in the suite; ``tools/fuzz.py`` the long one)."""
