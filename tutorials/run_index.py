"""The snapshots of the run that wrote an output folder, for the tutorials' analyse.py.

A folder may also hold snapshots an earlier run left there (a longer run's later files): the
run's own index, particles.xdmf, lists only its own (docs/scene-reference.md, "One run per
output folder").
"""
import os
import sys
import xml.etree.ElementTree as ET


def run_snapshots(folder):
    """The snapshot files of the run that wrote `folder`, in time order, from the run's own
    index particles.xdmf: snapshots an earlier run left in the folder are not listed there."""
    index = os.path.join(folder, "particles.xdmf")
    try:
        steps = ET.parse(index).getroot().find("Domain/Grid")
    except (OSError, ET.ParseError) as e:
        sys.exit(f"analyse.py: cannot read {index}, the run's list of its snapshots: {e}")
    files = [] if steps is None else \
        [os.path.join(folder, g.get("Name", "") + ".h5") for g in steps.findall("Grid")]
    if not files:
        sys.exit(f"analyse.py: {index} lists no snapshot")
    missing = [f for f in files if not os.path.isfile(f)]
    if missing:
        sys.exit(f"analyse.py: {missing[0]}, a snapshot {index} lists, is missing"
                 + (f" ({len(missing)} of its {len(files)} are)" if len(missing) > 1 else ""))
    return files
