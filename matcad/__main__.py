from matcad.cli import main

raise SystemExit(main())
