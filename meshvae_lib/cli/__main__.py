"""``python -m meshvae_lib.cli``: run one command and exit with its status (:func:`meshvae_lib.cli.run`,
the same entry point as the ``meshvae`` console script)."""

from meshvae_lib.cli import run

run()
