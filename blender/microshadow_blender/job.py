"""A microshadow call (render, bake) on a thread of its own, so that Blender's thread stays free to show
progress and take Esc: ctypes releases the GIL while the library works, and the library's progress callback
(called from one of its threads) only records the fraction and answers the cancel flag; every bpy call stays
on the thread that polls."""
import threading
import time


class Job:
    """fn(**kwargs, progress=...) on a thread; .warnings collects the library's warnings meanwhile (ms: the
    microshadow module, whose warning handler is process-wide)."""

    def __init__(self, ms, fn, **kwargs):
        self.fraction, self.cancel, self.result, self.error, self.warnings = 0.0, False, None, None, []
        self.started = time.time()
        ms.set_warning_handler(self.warnings.append)
        self._ms = ms
        kwargs["progress"] = self._progress
        self._thread = threading.Thread(target=self._run, args=(fn, kwargs), daemon=True)
        self._thread.start()

    def _progress(self, fraction):
        self.fraction = fraction
        return self.cancel

    def _run(self, fn, kwargs):
        try:
            self.result = fn(**kwargs)
        except Exception as e:  # handed to the polling thread, which reports it
            self.error = e
        finally:
            self._ms.set_warning_handler(None)

    def done(self):
        return not self._thread.is_alive()

    def wait(self, timeout=None):
        self._thread.join(timeout)
        return self.done()
