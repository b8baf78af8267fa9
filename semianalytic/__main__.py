import sys

from semianalytic.cli import main

sys.exit(main())
