"""``python -m virja`` is the ``virja`` command."""

from virja.cli.main import main

raise SystemExit(main())
