def solve_report(result):
    return "<html></html>"
