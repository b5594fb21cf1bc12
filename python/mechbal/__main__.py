import sys

from mechbal.cli import main

sys.exit(main())
