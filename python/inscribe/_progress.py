"""What a `progress=` argument may be, for every call that takes one (in-process and Client)."""


def progress_callback(progress):
    """`progress` as the callable(fraction) long calls report to, fraction in [0, 1]:
    None (no reports) and callables as they are; a progress bar (not callable, with
    update(n) and total: a tqdm.tqdm) advanced to fraction * total, its total set to 1.0 when
    it has none. TypeError for anything else."""
    if progress is None or callable(progress):
        return progress
    if not (callable(getattr(progress, "update", None)) and hasattr(progress, "total")):
        raise TypeError("progress must be None, a callable(fraction) or a progress bar with "
                        f"update(n) and total (tqdm.tqdm), got {type(progress).__name__}")
    if not progress.total:
        progress.total = 1.0
    reached = [0.0]

    def advance(fraction):
        target = fraction * progress.total
        if target > reached[0]:
            progress.update(target - reached[0])
            reached[0] = target

    return advance
