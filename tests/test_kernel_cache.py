"""Stale numba cache entries are dropped when any kernel source changes."""

from rollingtop import _kernel_cache


def _tree(tmp_path):
    for package in _kernel_cache.KERNEL_PACKAGES:
        (tmp_path / package / "__pycache__").mkdir(parents=True)
        (tmp_path / package / "mod.py").write_text(f"# {package}\n")
    (tmp_path / "cli.py").write_text("# not a kernel\n")
    return tmp_path


def _cache_files(root):
    return sorted(p.name for p in root.rglob("*") if p.suffix in (".nbi", ".nbc"))


def _fill_cache(root):
    for package in _kernel_cache.KERNEL_PACKAGES:
        (root / package / "__pycache__" / "mod.run-10.py311.nbi").write_bytes(b"index")
        (root / package / "__pycache__" / "mod.run-10.py311.1.nbc").write_bytes(b"code")
        (root / package / "__pycache__" / "mod.cpython-311.pyc").write_bytes(b"pyc")


def test_cache_kept_while_sources_unchanged_and_dropped_after_an_edit(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    root = _tree(tmp_path)
    _kernel_cache.refresh(root)  # first run: writes the stamp
    _fill_cache(root)
    assert not _kernel_cache.refresh(root)
    assert len(_cache_files(root)) == 6
    # an edit outside the kernels keeps the cache ...
    (root / "cli.py").write_text("# edited\n")
    assert not _kernel_cache.refresh(root)
    assert len(_cache_files(root)) == 6
    # ... an edit of any kernel module drops every cached kernel, not only that module's
    (root / "dynamics" / "mod.py").write_text("# dynamics, edited\n")
    assert _kernel_cache.refresh(root)
    assert _cache_files(root) == []
    assert (root / "integrate" / "__pycache__" / "mod.cpython-311.pyc").is_file()
    _fill_cache(root)
    assert not _kernel_cache.refresh(root)


def test_user_cache_dir_is_cleaned_too(tmp_path, monkeypatch):
    root = _tree(tmp_path / "pkg")
    user = tmp_path / "numba-cache"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(user))
    _kernel_cache.refresh(root)
    elsewhere = user / _kernel_cache.numba_subpath(root / "integrate")
    elsewhere.mkdir(parents=True)
    (elsewhere / "mod.run-10.py311.nbi").write_bytes(b"index")
    (root / "contact" / "mod.py").write_text("# edited\n")
    assert _kernel_cache.refresh(root)
    assert not any(elsewhere.iterdir())


def test_digest_covers_paths_and_contents(tmp_path):
    root = _tree(tmp_path)
    first = _kernel_cache.sources_digest(root)
    (root / "contact" / "mod.py").rename(root / "contact" / "other.py")
    assert _kernel_cache.sources_digest(root) != first


def test_unsavable_cache_is_a_warning_not_an_error(monkeypatch):
    """A full disk or a file-size limit while numba saves a compiled kernel: one warning naming
    the file and the reason, the kernel runs from memory (no exception escapes)."""
    import errno
    import warnings

    from numba.core.caching import Cache

    from rollingtop import _kernel_cache

    monkeypatch.setattr(_kernel_cache, "_warned", False)
    cache = Cache.__new__(Cache)  # numba's class with its guard; only the save itself is faked

    def fail(sig, data):
        raise OSError(errno.EFBIG, "File too large", "/cache/kernel.nbc")

    cache._save_overload = fail
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        cache.save_overload(None, None)
        cache.save_overload(None, None)  # reported once only
    assert [type(w.message) for w in caught] == [_kernel_cache.CacheNotSaved]
    message = str(caught[0].message)
    assert "/cache/kernel.nbc" in message and "File too large" in message
