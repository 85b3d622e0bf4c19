"""A minimal binding of LCM's C library (liblcm.so.1) through ctypes.

Debian 12 ships LCM for C, C++, Java and Lua but no Python module, so this binds the five
calls a client needs: lcm_create, lcm_publish, lcm_subscribe (with a C callback),
lcm_handle_timeout and lcm_destroy (plus lcm_unsubscribe). It moves bytes only; the
generated types (package ``kinograph``) encode and decode them. Not thread-safe: use one
Lcm per thread.
"""

import ctypes


class LcmError(RuntimeError):
    """LCM could not be loaded, opened or used; the message says which and why."""


class _RecvBuf(ctypes.Structure):
    # lcm_recv_buf_t of <lcm/lcm.h>
    _fields_ = [("data", ctypes.c_void_p), ("data_size", ctypes.c_uint32),
                ("recv_utime", ctypes.c_int64), ("lcm", ctypes.c_void_p)]


_HANDLER = ctypes.CFUNCTYPE(None, ctypes.POINTER(_RecvBuf), ctypes.c_char_p, ctypes.c_void_p)
_lib = None


def _liblcm():
    """liblcm.so.1 with its functions' signatures declared, loaded on first use."""
    global _lib
    if _lib is None:
        try:
            lib = ctypes.CDLL("liblcm.so.1")
        except OSError as e:
            raise LcmError(f"cannot load liblcm.so.1 (Debian package liblcm1): {e}") from None
        lib.lcm_create.restype = ctypes.c_void_p
        lib.lcm_create.argtypes = [ctypes.c_char_p]
        lib.lcm_destroy.restype = None
        lib.lcm_destroy.argtypes = [ctypes.c_void_p]
        lib.lcm_publish.restype = ctypes.c_int
        lib.lcm_publish.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_void_p,
                                    ctypes.c_uint]
        lib.lcm_subscribe.restype = ctypes.c_void_p
        lib.lcm_subscribe.argtypes = [ctypes.c_void_p, ctypes.c_char_p, _HANDLER,
                                      ctypes.c_void_p]
        lib.lcm_unsubscribe.restype = ctypes.c_int
        lib.lcm_unsubscribe.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
        lib.lcm_handle_timeout.restype = ctypes.c_int
        lib.lcm_handle_timeout.argtypes = [ctypes.c_void_p, ctypes.c_int]
        _lib = lib
    return _lib


class Subscription:
    """What Lcm.subscribe returns; pass it to Lcm.unsubscribe to stop the deliveries."""

    def __init__(self, handle, callback, channel):
        self._handle = handle
        # Kept so that the C function pointer outlives the subscription.
        self._callback = callback
        self.channel = channel


class Lcm:
    """One LCM instance on a URL (None: LCM's default, $LCM_DEFAULT_URL or udpm).

    Raises LcmError when LCM refuses the URL, e.g. udpm without a multicast route.
    """

    def __init__(self, url=None):
        self._lib = _liblcm()
        self.url = url
        self._lcm = self._lib.lcm_create(url.encode() if url is not None else None)
        if not self._lcm:
            where = url if url is not None else "the default URL"
            raise LcmError(f"LCM cannot open {where} (liblcm printed the reason on stderr)")
        self._subscriptions = []
        self._handler_error = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _check_open(self):
        if not self._lcm:
            raise LcmError("this Lcm is closed")

    def publish(self, channel, data):
        """Sends the bytes `data` (an encoded message) on `channel`."""
        self._check_open()
        if self._lib.lcm_publish(self._lcm, channel.encode(), data, len(data)) != 0:
            raise LcmError(f"LCM could not publish {len(data)} bytes on {channel}")

    def subscribe(self, channel, handler):
        """Calls handler(channel, data) for each message whose channel matches the regular
        expression `channel`, from inside handle(). Returns a Subscription."""
        self._check_open()

        def on_message(rbuf, c_channel, _user):
            # An exception cannot cross the C frames: keep it for handle() to raise.
            if self._handler_error is not None:
                return
            try:
                buf = rbuf.contents
                handler(c_channel.decode(), ctypes.string_at(buf.data, buf.data_size))
            except BaseException as e:  # noqa: B902 -- re-raised by handle()
                self._handler_error = e

        callback = _HANDLER(on_message)
        handle = self._lib.lcm_subscribe(self._lcm, channel.encode(), callback, None)
        if not handle:
            raise LcmError(f"LCM could not subscribe to {channel}")
        subscription = Subscription(handle, callback, channel)
        self._subscriptions.append(subscription)
        return subscription

    def unsubscribe(self, subscription):
        """Stops the deliveries of a subscribe()."""
        self._check_open()
        if subscription not in self._subscriptions:
            raise LcmError(f"not a subscription of this Lcm: {subscription.channel}")
        self._subscriptions.remove(subscription)
        if self._lib.lcm_unsubscribe(self._lcm, subscription._handle) != 0:
            raise LcmError(f"LCM could not unsubscribe from {subscription.channel}")

    def handle(self, timeout_s):
        """Waits up to `timeout_s` seconds for one message and dispatches it to the handlers.
        Returns True if a message was handled, False on timeout; re-raises a handler's
        exception."""
        self._check_open()
        status = self._lib.lcm_handle_timeout(self._lcm, max(0, round(timeout_s * 1000)))
        error, self._handler_error = self._handler_error, None
        if error is not None:
            raise error
        if status < 0:
            raise LcmError(f"LCM failed while receiving on {self.url or 'the default URL'}")
        return status > 0

    def close(self):
        """Releases the instance; further calls raise LcmError. Closing twice is harmless."""
        if self._lcm:
            self._lib.lcm_destroy(self._lcm)
            self._lcm = None
            self._subscriptions = []
