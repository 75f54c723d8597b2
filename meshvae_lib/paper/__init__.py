"""The paper's experiments (Sec. 5): settings, one module per experiment, recorded results and plots."""
