"""``python -m benchmarks.adversarial``: the command line of :mod:`benchmarks.adversarial.cli`."""

from .cli import main

if __name__ == "__main__":
    main()
