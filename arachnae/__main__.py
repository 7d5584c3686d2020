from arachnae.cli import main

raise SystemExit(main())
