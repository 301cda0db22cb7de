"""The ``progress=`` option of the calls that can run for seconds (``check``, ``EnvMap``,
``read_brdf``, ``texture_uv``): ``None`` (nothing), ``True`` (a ``tqdm`` bar when tqdm is
installed, else one line per stage on stderr) or a callable ``f(what: str, fraction: float)``
called with the stage or item running and the part done, in [0, 1], non-decreasing, ending at 1.
An exception raised by the callable ends the call and propagates."""

import sys


def make(progress, desc):
    """(callback or None, close) for a ``progress=`` value."""
    if progress is None or progress is False:
        return None, None
    if progress is True:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            last = [None]

            def line(what, fraction):
                if what != last[0]:
                    last[0] = what
                    print(f"gonio {desc}: {what} ({100.0 * fraction:.0f} %)", file=sys.stderr, flush=True)

            return line, None
        bar = tqdm(total=1000, desc=f"gonio {desc}", bar_format="{desc}: {percentage:3.0f}%|{bar}| {postfix}",
                   leave=False)

        def update(what, fraction):
            bar.set_postfix_str(what, refresh=False)
            bar.n = max(0, min(1000, int(round(1000.0 * fraction))))
            bar.refresh()

        return update, bar.close
    if callable(progress):
        return progress, None
    raise TypeError(f"progress: None, True or a callable f(what, fraction), not {type(progress).__name__}")
