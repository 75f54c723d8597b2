import sys

from meshvae_lib.cli import main

sys.exit(main())
