"""Setup shared by the tests."""

import signal

# The tests of Ctrl-C send SIGINT as a terminal does. A shell that starts a job in the
# background without job control (`command &` in a script) starts it with SIGINT ignored,
# and Python then installs no KeyboardInterrupt handler, nor do the Pythons it starts:
# put it back, so the tests give the same verdict however they were started.
signal.signal(signal.SIGINT, signal.default_int_handler)
