"""Wrong answers to the exercises of notebook 06_conditional_vae: each must make its self-check raise.

Keys are exercise numbers from 1; values map a short description to the code run in place of
the solution (tests/test_exercise_checks.py runs them)."""

WRONG_ANSWERS = {
}
