"""A Python host program under time=virtual that waits for a BUSY edge an idle chip never makes,
through Debian's python3-libgpiod: on real hardware it hangs for ever; the emulator must end it
with its deadlock report. Usage: deadlock.py read | threads | timeout"""
import sys
import threading

import gpiod

mode = sys.argv[1] if len(sys.argv) > 1 else "read"
chip = gpiod.Chip("gpiochip0")
busy = chip.get_line(0)
busy.request(consumer="waiter", type=gpiod.LINE_REQ_EV_BOTH_EDGES)
print(f"mode {mode}", flush=True)

if mode == "read":
    busy.event_read()  # the only thread, waiting for an edge that never comes
elif mode == "threads":
    def watcher():
        busy.event_read()

    t = threading.Thread(target=watcher, name="watcher")
    t.start()
    t.join()  # the main thread waits for the watcher, which waits for the edge
elif mode == "timeout":
    # Not a deadlock: the wait has a timeout, which virtual time reaches at once.
    print(f"edge within 10 s: {busy.event_wait(sec=10)}", flush=True)
print("done", flush=True)
