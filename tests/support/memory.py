"""Peak resident memory of the calling process alone.

``getrusage(RUSAGE_SELF).ru_maxrss`` is no such figure in a child process: Linux carries the
parent's high-water mark over ``fork``/``vfork`` and ``exec`` (a trivial child of a 3 GB parent
reports 2.8 GB), so a child started by a pytest worker or a bench driver reported their peak.
``VmHWM`` belongs to the process's own address space, which ``exec`` makes new.
"""


def peak_resident_mb() -> float:
    """The high-water mark of this process's resident memory (``VmHWM``), in MiB."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    raise RuntimeError("/proc/self/status has no VmHWM line")
