"""The command line (cli.main: the parser and the commands) and the demo (demo).
"""
