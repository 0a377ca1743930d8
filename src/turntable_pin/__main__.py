"""``python -m turntable_pin`` runs the command line."""

import sys

from .core.interrupts import exit_on_signal, install_handlers, signal_name

install_handlers()  # before the command line's imports: Ctrl-C this early is no traceback either
try:
    from .cli import main

    status = main()
except KeyboardInterrupt as exc:  # before main() took over
    exit_on_signal("turntable-pin")
    signum = getattr(exc, "signum", 2)
    print(f"turntable-pin: interrupted ({signal_name(signum)})", file=sys.stderr)
    status = 128 + signum
sys.exit(status)
