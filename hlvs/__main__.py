import sys

from hlvs.cli import main

sys.exit(main())
