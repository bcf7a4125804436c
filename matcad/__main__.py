from matcad.entry import run

run()
