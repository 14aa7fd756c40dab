"""The BLAS threads of an `mpc` process: one, unless the user chose a number.

numpy's OpenBLAS starts a thread per core when it is loaded, and those threads spin for a
while after each call. mpc's matrices are 3×3 and 4×4: the threads never pay, and cost CPU
time (0.1 s of a warm build of TALOS on 2 cores). OpenBLAS reads OPENBLAS_NUM_THREADS once,
when numpy is first imported, so `mpc` sets it as it starts (`one_thread`). Programs that mpc
starts for the user (post_processing) get the user's environment back (`user_environment`).
What it does not do: limit other libraries' threads (the mesh pool is mpc's own choice).
"""

from __future__ import annotations

import os

VARIABLE = "OPENBLAS_NUM_THREADS"
_ours = False  # whether this process set VARIABLE (the user did not)


def one_thread() -> None:
    """Use one BLAS thread in this process and in mpc's own workers, unless the user set a number."""
    global _ours
    if VARIABLE not in os.environ:
        os.environ[VARIABLE] = "1"
        _ours = True
    elif os.environ[VARIABLE] != "1":  # set by the user (since): theirs
        _ours = False


def user_environment() -> dict[str, str]:
    """This process's environment as the user gave it: for the programs mpc starts on their behalf."""
    env = dict(os.environ)
    if _ours:
        env.pop(VARIABLE, None)
    return env
