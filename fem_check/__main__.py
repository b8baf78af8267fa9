import sys

from fem_check.cli import main

sys.exit(main())
