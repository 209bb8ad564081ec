"""One-rank runs as Open MPI singletons without the daemon (ess_singleton_isolated: the same
program, 0.2 s less per start), several at once.

Isolated singletons all take the same name, [0,1],0, and with it the same session directory,
<tmp>/ompi.<host>.<uid>/jf.0/1/0. One that ends removes the directory while another is making
it, and that one fails in MPI_Init ("A call to mkdir was unable to create the desired
directory ... jf.0/1"): 1 run in 8 of tests/dem/app/documented_defaults.py, 161 runs 4 at a
time, failed so. Each run here gets a base of its own for that directory (orte_tmpdir_base),
removed when it ends."""

import contextlib
import os
import shutil
import tempfile


@contextlib.contextmanager
def isolated_singleton(env=None):
    """The environment for one isolated singleton run: a copy of env (default os.environ) with
    its own session directory base, removed on leaving the block."""
    base = tempfile.mkdtemp(prefix="grainflow-ompi-")
    try:
        yield dict(os.environ if env is None else env, OMPI_MCA_ess_singleton_isolated="1",
                   OMPI_MCA_orte_tmpdir_base=base)
    finally:
        shutil.rmtree(base, ignore_errors=True)
