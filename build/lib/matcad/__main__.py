from matcad.cli import run

run()
