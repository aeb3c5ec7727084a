"""``python -m cyborg.app`` is the same as the ``cyborg`` command."""

from cyborg.app.cli import main

raise SystemExit(main())
