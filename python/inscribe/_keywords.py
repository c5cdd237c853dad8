"""Mistyped keywords named as Python names them.

pybind11 answers a call it cannot match with "incompatible function arguments" and every
signature the function has. For a keyword that no signature has, the wrappers here raise
TypeError("generate() got an unexpected keyword argument 'max_sphere'; did you mean
'max_spheres'?") instead, with the keywords the function takes; the names come from pybind11's
own message, so they cannot drift from the bindings. Other refusals pass through unchanged.
"""

import difflib
import functools
import re

_INCOMPATIBLE = re.compile(r"^(\w+)\(\): incompatible (?:function|constructor) arguments")
_SIGNATURE = re.compile(r"^\s*\d+\. (.*)$", re.M)
_PARAMETER = re.compile(r"(?:\(|, )(\w+): ")


def _unknown_keyword_error(qualname, error, keywords):
    """The TypeError naming the first of `keywords` that no signature in pybind11's `error`
    takes, or None when every one is taken (the types were wrong, not the names)."""
    message = str(error)
    if not _INCOMPATIBLE.match(message):
        return None
    taken = {name for signature in _SIGNATURE.findall(message)
             for name in _PARAMETER.findall(signature)} - {"self"}
    for keyword in keywords:
        if keyword not in taken:
            close = difflib.get_close_matches(keyword, sorted(taken), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            return TypeError(f"{qualname}() got an unexpected keyword argument {keyword!r}{hint} "
                             f"(it takes {', '.join(sorted(taken)) or 'no keywords'})")
    return None


def _named(function, qualname):
    @functools.wraps(function)
    def call(*args, **kwargs):
        try:
            return function(*args, **kwargs)
        except TypeError as error:
            if not kwargs:
                raise
            named = _unknown_keyword_error(qualname, error, kwargs)
            if named is None:
                raise
            raise named from None
    return call


def _is_binding(value):
    return type(value).__name__ in ("builtin_function_or_method", "instancemethod")


def name_unknown_keywords(module):
    """Wraps every public function of the extension `module`, and every public method and
    constructor of its classes, in place."""
    for name, value in list(vars(module).items()):
        if name.startswith("_"):
            continue
        if _is_binding(value):
            setattr(module, name, _named(value, name))
        elif isinstance(value, type) and value.__module__ == module.__name__:
            for attribute, method in list(vars(value).items()):
                if (attribute == "__init__" or not attribute.startswith("_")) and \
                        _is_binding(method):
                    setattr(value, attribute, _named(method, f"{name}.{attribute}"
                                                     if attribute != "__init__" else name))
