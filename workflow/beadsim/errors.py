"""Exceptions with messages a user can act on."""


class ConfigError(ValueError):
    """A config value is wrong; the message names the key and what is allowed."""


class SimulationFailed(RuntimeError):
    """A simulation stopped for a numerical or physical reason (watchdog trip, lost atoms, NaN, ...).

    Parameters
    ----------
    reason : str
        One line a user can read, e.g. "density 0.71 rho0 below 0.8 at t=0.084 s".
    metrics : dict, optional
        Whatever was measured before the failure (wall time, steps, time reached).
    """

    def __init__(self, reason: str, metrics: dict | None = None):
        super().__init__(reason)
        self.reason = reason
        self.metrics = dict(metrics or {})


class RankFailure(SimulationFailed):
    """A failure on one MPI rank alone (a LAMMPS error raised on one rank, a Python error in the driver there).

    The other ranks may be waiting for this one inside LAMMPS or in a collective, so the run cannot wind down
    together: the rank writes what it knows and aborts the job (:mod:`beadsim.sph.mpi_main`). Its metrics are
    this rank's own, gathered without communication.
    """
