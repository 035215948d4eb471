"""Batch runs: one ``crease`` command per file, on a local process pool or a dask cluster.

Each task runs the CLI's own code in the worker process (:func:`crease.command`), so a batch
writes exactly what the CLI writes. Outputs are written atomically by the CLI (a temporary file
renamed into place), so an output that exists is complete: a rerun skips it unless its input is
newer, and a batch that was interrupted resumes where it stopped.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from typing import Any, Dict, Iterable, List, Optional, Sequence, Tuple, Union

PathLike = Union[str, "os.PathLike[str]"]

#: Each task's CLI command and the files it writes per input (``{stem}`` is the input's file
#: name without its extension). The first file is the command's ``-o``; ``run`` writes a folder,
#: whose ``summary.json`` it writes last.
TASKS: Dict[str, Tuple[str, Tuple[str, ...]]] = {
    "sharp": ("sharp", ("{stem}.ply",)),
    "normals": ("normals", ("{stem}.ply",)),
    "curvature": ("curvature", ("{stem}.ply",)),
    "lines": ("lines", ("{stem}.obj",)),
    "fillets": ("fillets", ("{stem}.obj",)),
    "network": ("network", ("{stem}.obj",)),
    "segment": ("segment", ("{stem}.ply", "{stem}.json")),
    "edges": ("edges", ("{stem}.ply",)),
    "reconstruct": ("reconstruct", ("{stem}.step",)),
    "run": ("run", ("{stem}", "{stem}/summary.json")),
}


@dataclass
class BatchReport:
    """What :func:`batch` did.

    Attributes:
        done: per file computed, ``(input, first output, seconds)``.
        skipped: inputs whose outputs existed and were newer than the input.
        failed: per file that failed, ``(input, message)`` (the CLI's message, naming the file).
        seconds: the batch's wall-clock time.
    """

    done: List[Tuple[str, str, float]] = field(default_factory=list)
    skipped: List[str] = field(default_factory=list)
    failed: List[Tuple[str, str]] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """True when no file failed."""
        return not self.failed

    def __repr__(self) -> str:
        return (
            f"BatchReport(done={len(self.done)}, skipped={len(self.skipped)}, "
            f"failed={len(self.failed)}, seconds={self.seconds:.2f})"
        )


def cli_options(params: Dict[str, Any]) -> List[str]:
    """Keyword parameters as CLI options: ``k=20`` -> ``-k 20``, ``region_angle=8`` ->
    ``--region-angle 8``, ``orient=True`` -> ``--orient``, ``surfaces=False`` ->
    ``--no-surfaces``, ``scales=[12, 16]`` -> ``--scales 12,16``; ``None`` is left out."""
    out: List[str] = []
    for name, value in params.items():
        if value is None:
            continue
        flag = "-k" if name == "k" else "--" + name.replace("_", "-")
        if value is True:
            out.append(flag)
        elif value is False:
            out.append("--no-" + name.replace("_", "-"))
        elif isinstance(value, (list, tuple)):
            out += [flag, ",".join(str(v) for v in value)]
        else:
            out += [flag, str(value)]
    return out


def _outputs(task: str, path: str, out_dir: str) -> List[str]:
    stem = os.path.splitext(os.path.basename(path))[0]
    return [os.path.join(out_dir, f.format(stem=stem)) for f in TASKS[task][1]]


def _up_to_date(path: str, outputs: Sequence[str]) -> bool:
    """Every output exists (complete, as the CLI writes atomically) and is not older than the
    input (the last file of ``run``'s list is the one it writes last)."""
    try:
        t_in = os.stat(path).st_mtime
        return all(os.stat(o).st_mtime >= t_in for o in outputs)
    except OSError:
        return False


def _run_job(job: Tuple[str, str, List[str], Optional[int], List[str]]) -> Dict[str, Any]:
    """A job with its CLI options: the worker entry point (a module-level function, so that
    process pools and dask can pickle it)."""
    from . import _crease

    task, path, outputs, threads, options = job
    command = TASKS[task][0]
    args: List[str] = ["--quiet"]
    if threads is not None:
        args += ["--threads", str(threads)]
    args += [command, path, "-o", outputs[0]]
    if task == "segment":
        args += ["--primitives", outputs[1]]
    args += options
    start = time.perf_counter()
    try:
        _crease.command(args, True)
        error = None
    except Exception as e:  # noqa: BLE001: a worker reports every failure as its message
        error = str(e) or type(e).__name__
    return {
        "input": path,
        "output": outputs[0],
        "seconds": time.perf_counter() - start,
        "error": error,
    }


def _worker_failed(job: Tuple[Any, ...], e: BaseException) -> Dict[str, Any]:
    """The result of a job whose worker died (a crash, killed for memory): that file's failure."""
    return {"input": job[1], "output": job[2][0], "seconds": 0.0, "error": f"{job[1]}: the worker failed: {e!r}"}


def _set_threads(n: Optional[int]) -> None:
    """A pool worker's initialiser: its computations use ``n`` threads."""
    if n:
        from . import _crease

        try:
            _crease.set_num_threads(n)
        except RuntimeError:
            pass


def map_tasks(
    fn: Any,
    jobs: Sequence[Any],
    client: Any = None,
    workers: int = 1,
    threads: Optional[int] = None,
    bar: Any = None,
    recover: Any = None,
) -> List[Any]:
    """``[fn(j) for j in jobs]`` run as tasks: on the dask ``client``'s workers, on a local pool
    of ``workers`` fresh processes using ``threads`` threads each, or here when ``workers`` is
    1. ``fn`` is a module-level function (pickled by reference). Results in the order of
    ``jobs``. A task that raises raises here, unless ``recover(job, exception)`` gives its
    result instead."""
    if not jobs:
        return []

    def result(fut: Any, job: Any) -> Any:
        try:
            return fut.result()
        except Exception as e:  # noqa: BLE001
            if recover is None:
                raise
            return recover(job, e)

    def tick() -> None:
        if bar is not None:
            bar.update(1)

    if client is not None:
        from distributed import as_completed

        futures = client.map(fn, jobs, pure=False)
        for _ in as_completed(futures):
            tick()
        return [result(f, j) for f, j in zip(futures, jobs)]
    if workers <= 1:
        out = []
        for j in jobs:
            out.append(fn(j))
            tick()
        return out
    import concurrent.futures as cf
    import multiprocessing as mp

    # Fresh interpreters: a forked child would inherit the parent's thread pools.
    ctx = mp.get_context("spawn")
    with cf.ProcessPoolExecutor(
        max_workers=workers, mp_context=ctx, initializer=_set_threads, initargs=(threads,)
    ) as pool:
        futures = [pool.submit(fn, j) for j in jobs]
        for _ in cf.as_completed(futures):
            tick()
        return [result(f, j) for f, j in zip(futures, jobs)]


def _progress(total: int, enabled: bool) -> Any:
    """A tqdm bar when tqdm is installed and ``enabled``, else None."""
    if not enabled:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    return tqdm(total=total, unit="file")


def batch(
    paths: Iterable[PathLike],
    task: str,
    out_dir: PathLike,
    client: Any = None,
    workers: Optional[int] = None,
    threads: Optional[int] = None,
    overwrite: bool = False,
    progress: bool = True,
    **params: Any,
) -> BatchReport:
    """Runs ``crease TASK`` on every file of ``paths``, writing what the CLI writes into
    ``out_dir`` (created if missing): ``sharp``, ``normals``, ``curvature``, ``segment``,
    ``edges`` -> ``STEM.ply`` (``segment`` also ``STEM.json``, its surfaces); ``lines``,
    ``fillets``, ``network`` -> ``STEM.obj``; ``reconstruct`` -> ``STEM.step``; ``run`` -> the
    folder ``STEM/``.

    ``params`` are the command's options as keywords (``k=20``, ``region_angle=8``,
    ``surfaces=False`` for ``--no-surfaces``; see :func:`cli_options`).

    With a ``dask.distributed`` ``client``, one task per file runs on the cluster's workers
    (which need crease installed and the paths readable). Without one, a local pool of
    ``workers`` processes (default: one per core, at most one per file), each command using
    ``threads`` threads (default: the cores shared among the workers; with dask: all cores).

    Resumable: a file whose outputs exist and are not older than it is skipped (the CLI writes
    each output atomically, so an existing output is complete) unless ``overwrite``. A file that
    fails is reported in the result's ``failed`` with the CLI's message and does not stop the
    others. A progress bar is shown when tqdm is installed and ``progress`` is true.

    Raises ``ValueError`` for an unknown task or two inputs that would write the same output
    (same file name in different folders), before anything runs.
    """
    if task not in TASKS:
        raise ValueError(f"unknown task {task!r}; one of {', '.join(TASKS)}")
    start = time.perf_counter()
    out = os.fspath(out_dir)
    os.makedirs(out, exist_ok=True)
    options = cli_options(params)
    inputs = [os.fspath(p) for p in paths]
    seen: Dict[str, str] = {}
    for p in inputs:
        first = _outputs(task, p, out)[0]
        if first in seen and seen[first] != p:
            raise ValueError(f"{seen[first]} and {p} would both write {first}")
        seen[first] = p
    report = BatchReport()
    todo = []
    for p in dict.fromkeys(inputs):
        outputs = _outputs(task, p, out)
        if not overwrite and _up_to_date(p, outputs):
            report.skipped.append(p)
        else:
            todo.append(p)
    cores = os.cpu_count() or 1
    if client is None:
        workers = max(1, min(workers or cores, len(todo) or 1))
        if threads is None:
            threads = max(1, cores // workers)
    jobs = [(task, p, _outputs(task, p, out), threads, options) for p in todo]
    bar = _progress(len(jobs), progress)

    try:
        results = map_tasks(_run_job, jobs, client, workers or 1, None, bar, recover=_worker_failed)
    finally:
        if bar is not None:
            bar.close()
    for r in results:
        if r.get("error") is None:
            report.done.append((r["input"], r["output"], r["seconds"]))
        else:
            report.failed.append((r["input"], r["error"]))
    report.seconds = time.perf_counter() - start
    return report
