"""Audio and motion beats, and the Gaussian alignment score shared by BeatAlign and BC.

Audio beats are onsets (librosa ``onset_strength`` + ``onset_detect``). Motion beats are
moments where the motion pauses: local minima of joint speed (BEAT) or of the normalised
mean change of the angles between bones (HA2G). The score of one set against another is

    score(Q -> R) = (1 / |Q|) sum_{q in Q} exp(-min_{r in R} (q - r)^2 / (2 sigma^2)),

i.e. for every *query* beat the Gaussian of its distance to the nearest *reference* beat.
Both reference codes query with the audio beats (audio -> motion).

Taught in notebooks/03_audio_and_text_features.ipynb, sections 3-4 (onsets; onsets and pauses in the motion) and notebooks/04_metrics.ipynb, section 3.2 (the beats of a take).
"""

from __future__ import annotations

import numpy as np

from beatlite.metrics._checks import as_array, positive

#: librosa's default sample rate; the BEAT reference silently used it for 16 kHz audio.
LIBROSA_DEFAULT_SR = 22050
DIRECTIONS = ("audio_to_motion", "motion_to_audio", "symmetric")
BACKTRACKS = (None, "rms", "onset")


# ----------------------------------------------------------------------------- audio
def audio_beats(
    audio: np.ndarray,
    sr: int,
    *,
    hop_length: int = 512,
    n_fft: int = 2048,
    backtrack: str | None = None,
    legacy_sr: bool = False,
    peak_pick: str = "beatlite",
) -> np.ndarray:
    """Onset times of an audio signal, in seconds.

    ``onset_strength`` (mean positive log-mel flux, 128 mels, ``n_fft`` 2048) followed by
    ``onset_detect`` peak picking (librosa defaults). The STFT is computed once and shared
    by the onset envelope and the optional RMS backtracking.

    Parameters
    ----------
    audio : (N,) float
        Mono waveform in [-1, 1].
    sr : int
        Its sample rate in Hz (beatlite: 16000).
    hop_length, n_fft : int
        STFT hop and size in samples (librosa defaults 512 and 2048).
    backtrack : None, "rms" or "onset"
        Move each onset back to the preceding local minimum of the frame RMS energy
        (``"rms"``, the BEAT reference) or of the onset envelope (``"onset"``, librosa's
        ``backtrack=True``). ``None`` (HA2G, librosa's default) keeps the peaks.
    legacy_sr : bool
        Reproduce the BEAT reference bug: peak picking and ``frames_to_time`` ran with
        librosa's default ``sr=22050`` although the audio is 16 kHz, so every time is
        scaled by ``sr / 22050`` (0.726 at 16 kHz) and the peak-picking windows change.
    peak_pick : "beatlite" or "librosa"
        librosa's peak-picking windows are 30 ms (max, wait) and 100 ms (average) rounded
        *down* to frames; at 16 kHz with hop 512 the 30 ms windows become 0 frames and the
        look-ahead is none, so every rising frame above the local average is an onset and one
        click can yield 2-3 onsets. ``"beatlite"`` requires an onset to be the envelope maximum
        within +-100 ms and 100 ms after the previous one (``pre_max = post_max = wait =
        round(0.1 sr / hop)``, 3 frames at 16 kHz); ``"librosa"`` keeps librosa's defaults
        exactly (HA2G's ``onset_detect(y, sr=16000)``; BEAT's call with ``legacy_sr``).

    Returns
    -------
    (A,) float64
        Increasing onset times in seconds from the first sample.

    Examples
    --------
    >>> sr = 16000
    >>> audio = np.zeros(3 * sr, dtype=np.float32)
    >>> audio[[sr // 2, 3 * sr // 2]] = 1.0  # clicks at 0.5 s and 1.5 s
    >>> audio_beats(audio, sr).round(1).tolist()  # to the nearest hop of 512 samples (32 ms)
    [0.5, 1.5]
    """
    import librosa
    from scipy import sparse

    y = as_array(audio, "audio", ndim=1, dtype=np.float32)
    sr = int(positive(sr, "sr"))
    if backtrack not in BACKTRACKS:
        raise ValueError(f"backtrack must be one of {BACKTRACKS}, got {backtrack!r}")
    if y.size < 2:
        return np.zeros(0, dtype=np.float64)
    spec = stft_magnitude(y, n_fft=n_fft, hop_length=hop_length)
    mel_basis = sparse.csr_matrix(librosa.filters.mel(sr=sr, n_fft=n_fft, fmax=0.5 * sr))
    mel = mel_basis @ (spec * spec)  # = librosa.feature.melspectrogram(S=spec**2); the basis is sparse
    env = librosa.onset.onset_strength(S=librosa.power_to_db(mel), sr=sr, hop_length=hop_length, n_fft=n_fft)
    pick_sr = LIBROSA_DEFAULT_SR if legacy_sr else sr
    if peak_pick not in ("beatlite", "librosa"):
        raise ValueError(f"peak_pick must be 'beatlite' or 'librosa', got {peak_pick!r}")
    kwargs = {}
    if peak_pick == "beatlite":
        k = max(1, int(round(0.1 * pick_sr / hop_length)))
        kwargs = {"pre_max": k, "post_max": k + 1, "wait": k}
    frames = librosa.onset.onset_detect(
        onset_envelope=env, sr=pick_sr, hop_length=hop_length, backtrack=False, **kwargs
    )
    if backtrack == "rms":
        energy = librosa.feature.rms(S=spec, frame_length=n_fft, hop_length=hop_length)[0]
        frames = librosa.onset.onset_backtrack(frames, energy)
    elif backtrack == "onset":
        frames = librosa.onset.onset_backtrack(frames, env)
    return np.asarray(frames, dtype=np.float64) * hop_length / pick_sr


_WARM: list[bool] = []


def warm_up() -> None:
    """Compile, once per process, the numba functions of librosa that :func:`audio_beats` runs (onset strength,
    both peak pickers, both backtracks).

    Call it before starting worker processes that detect onsets (``retrain-all --jobs``): numba keeps
    compiled code in an on-disk cache, and several fresh processes compiling the same functions at once can
    corrupt it (numba#10128, librosa#1998: every later ``onset_detect`` then segfaults). Compiled here
    first, the workers only read the cache. About 20 s in a fresh environment, instant afterwards.

    Examples
    --------
    >>> warm_up()  # later calls return at once
    """
    if _WARM:
        return
    y = (0.1 * np.sin(np.arange(16000) * 0.05) * (np.arange(16000) % 4000 < 400)).astype(np.float32)
    for pick in ("beatlite", "librosa"):
        for backtrack in (None, "rms", "onset"):
            audio_beats(y, 16000, peak_pick=pick, backtrack=backtrack)
    _WARM.append(True)


def stft_magnitude(
    y: np.ndarray, *, n_fft: int = 2048, hop_length: int = 512, chunk: int = 2048
) -> np.ndarray:
    """``|librosa.stft(y, n_fft, hop_length)|`` computed in float32 chunks with ``scipy.fft``.

    Same framing as librosa's defaults: centred frames (``n_fft // 2`` zeros on each side),
    periodic Hann window, ``1 + len(y) // hop_length`` frames.

    Parameters
    ----------
    y : (N,) float32 waveform
    n_fft, hop_length : int
    chunk : int
        Frames transformed at once (bounds the temporary memory).

    Returns
    -------
    (1 + n_fft // 2, 1 + N // hop_length) float32 magnitudes.

    Examples
    --------
    >>> y = np.zeros(16000, dtype=np.float32)
    >>> stft_magnitude(y).shape  # (1 + 2048 // 2, 1 + 16000 // 512)
    (1025, 32)
    """
    import scipy.fft
    from scipy.signal import get_window

    y = np.ascontiguousarray(y, dtype=np.float32)
    pad = np.pad(y, n_fft // 2)
    n_frames = 1 + (len(pad) - n_fft) // hop_length
    frames = np.lib.stride_tricks.as_strided(
        pad, shape=(n_frames, n_fft), strides=(pad.strides[0] * hop_length, pad.strides[0]), writeable=False
    )
    window = get_window("hann", n_fft, fftbins=True).astype(np.float32)
    out = np.empty((1 + n_fft // 2, n_frames), dtype=np.float32)
    for a in range(0, n_frames, chunk):
        out[:, a : a + chunk] = np.abs(scipy.fft.rfft(frames[a : a + chunk] * window, axis=1)).T
    return out


# ----------------------------------------------------------------------------- motion speed
def position_speed(positions: np.ndarray, fps: float) -> np.ndarray:
    """Per-joint speed by central differences (forward/backward at the ends).

    ``v_t = ||p_{t+1} - p_{t-1}|| * fps / 2`` (``numpy.gradient``).

    Why central differences here: a motion beat is a *time* (the frame where the joint pauses).
    The central difference is the speed *at* frame t, so a pause at frame t gives its minimum at t;
    a forward difference ``||p_{t+1} - p_t||`` is the speed between t and t + 1 and would time every
    beat half a frame (33 ms at 15 fps) late. :func:`euler_speed` keeps the forward differences of
    BEAT's reference code on purpose; :func:`beatlite.metrics.extras.velocity_stats` uses them too,
    because it summarises magnitudes, where the half-frame shift does not matter and the n-th
    difference family (speed, jerk) stays consistent.

    Parameters
    ----------
    positions : (T, J, 3) float, centimetres
    fps : float

    Returns
    -------
    (T, J) float64, centimetres per second.

    Examples
    --------
    >>> positions = np.zeros((4, 1, 3))
    >>> positions[:, 0, 0] = [0.0, 1.0, 2.0, 4.0]  # cm
    >>> position_speed(positions, fps=10)[:, 0]  # cm/s
    array([10., 10., 15., 20.])
    """
    p = as_array(positions, "positions", ndim=3, last=3)
    if p.shape[0] < 2:
        raise ValueError(f"positions needs at least 2 frames, got shape {p.shape}")
    vel = np.gradient(p, 1.0 / positive(fps, "fps"), axis=0)
    return np.linalg.norm(vel, axis=-1)


def euler_speed(channels: np.ndarray, columns: np.ndarray | list[int], fps: float) -> np.ndarray:
    """Euler-angle speed of channel triplets by forward frame differences (the BEAT reference).

    ``v_{t,k} = ||r_{t+1,k} - r_{t,k}|| * fps`` for each triplet ``k`` of ``columns``.

    Parameters
    ----------
    channels : (T, C) float, degrees
        Euler angles (e.g. the 141 ``spine_neck_141`` channels, or the 228 BVH channels).
    columns : (3K,) int
        Channel columns, grouped in consecutive triplets.
    fps : float

    Returns
    -------
    (T - 1, K) float64, degrees per second; sample ``t`` lies between frames t and t+1 and,
    as in the reference, is timed at ``t / fps``.

    Examples
    --------
    >>> channels = np.zeros((3, 6))
    >>> channels[:, 3] = [0.0, 3.0, 7.0]  # x rotation of the second triplet, degrees
    >>> euler_speed(channels, [3, 4, 5], fps=10)  # (T - 1, K) degrees per second
    array([[30.],
           [40.]])
    """
    x = as_array(channels, "channels", ndim=2)
    cols = np.asarray(columns, dtype=np.int64).ravel()
    if cols.size == 0 or cols.size % 3:
        raise ValueError(f"columns must hold whole triplets (3K indices), got {cols.size}")
    if cols.min() < -x.shape[1] or cols.max() >= x.shape[1]:
        raise ValueError(f"columns {cols.tolist()} out of range for channels of shape {x.shape}")
    if x.shape[0] < 2:
        raise ValueError(f"channels needs at least 2 frames, got shape {x.shape}")
    d = np.diff(x[:, cols], axis=0).reshape(x.shape[0] - 1, -1, 3)
    return np.linalg.norm(d, axis=-1) * positive(fps, "fps")


def local_minima(curve: np.ndarray, order: int = 2) -> np.ndarray:
    """Indices of strict local minima over ``order`` neighbours on each side.

    Index ``t`` qualifies when ``x_t < x_{t+k}`` and ``x_t < x_{t-k}`` for ``k = 1..order``,
    neighbours beyond the ends clipped to the end sample (so the ends never qualify) —
    ``scipy.signal.argrelextrema(x, np.less, order=order)``.

    Parameters
    ----------
    curve : (T,) float
    order : int >= 1

    Returns
    -------
    (K,) int64 increasing indices.

    Examples
    --------
    >>> local_minima(np.array([3.0, 2, 1, 2, 3, 2, 0, 2, 3]), order=2)
    array([2, 6])
    """
    x = np.asarray(curve, dtype=np.float64)
    if x.ndim != 1:
        raise ValueError(f"curve must be 1-D, got shape {x.shape}")
    if int(order) < 1:
        raise ValueError(f"order must be >= 1, got {order}")
    n = x.shape[0]
    if n < 3:
        return np.zeros(0, dtype=np.int64)
    keep = np.ones(n, dtype=bool)
    idx = np.arange(n)
    for k in range(1, int(order) + 1):
        keep &= x < x[np.minimum(idx + k, n - 1)]
        keep &= x < x[np.maximum(idx - k, 0)]
    return np.flatnonzero(keep).astype(np.int64)


# ----------------------------------------------------------------------------- HA2G angles
def append_palm_normals(directions: np.ndarray) -> np.ndarray:
    """Append HA2G's two palm normals to the 42 TED direction vectors.

    ``n_left = cross(v11, v17)``, ``n_right = cross(v28, v34)``, both normalised (a zero
    cross product stays zero) — :func:`beatlite.skeleton.ted.palm_normals`.

    Parameters
    ----------
    directions : (T, 42, 3) float
        TED-43 bone direction vectors (not mean-subtracted).

    Returns
    -------
    (T, 44, 3) float64

    Examples
    --------
    >>> directions = np.zeros((1, 42, 3))
    >>> directions[:, [11, 28]] = [1, 0, 0]
    >>> directions[:, [17, 34]] = [0, 1, 0]
    >>> out = append_palm_normals(directions)
    >>> out.shape, out[0, 42:].tolist()
    ((1, 44, 3), [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]])
    """
    from beatlite.skeleton.ted import palm_normals

    d = as_array(directions, "directions", ndim=3, last=3)
    if d.shape[1] != 42:
        raise ValueError(f"directions must be (T, 42, 3) TED direction vectors, got shape {d.shape}")
    return np.concatenate([d, palm_normals(d)], axis=1)


def included_angles(directions: np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """Angles between pairs of vectors, divided by pi.

    ``theta_{t,p} = arccos(<u_a, u_b> / (|u_a| |u_b|)) / pi`` for pair ``p = (a, b)``.

    Parameters
    ----------
    directions : (T, V, 3) float
    pairs : (P, 2) int
        Indices into the V vectors.

    Returns
    -------
    (T, P) float64 in [0, 1] (units of pi radians).

    Examples
    --------
    >>> directions = np.array([[[1.0, 0, 0], [0, 2, 0], [-1, 0, 0]]])
    >>> included_angles(directions, np.array([[0, 1], [0, 2]]))  # 90 and 180 degrees, in units of pi
    array([[0.5, 1. ]])
    """
    d = as_array(directions, "directions", ndim=3, last=3)
    pr = np.asarray(pairs, dtype=np.int64)
    if pr.ndim != 2 or pr.shape[1] != 2:
        raise ValueError(f"pairs must be (P, 2) indices, got shape {pr.shape}")
    if pr.size and (pr.min() < 0 or pr.max() >= d.shape[1]):
        raise ValueError(f"pairs index vectors up to {pr.max()} but directions has {d.shape[1]} vectors")
    a, b = d[:, pr[:, 0]], d[:, pr[:, 1]]
    denom = np.linalg.norm(a, axis=-1) * np.linalg.norm(b, axis=-1)
    cos = np.divide((a * b).sum(-1), denom, out=np.ones_like(denom), where=denom > 1e-12)
    return np.arccos(np.clip(cos, -1.0, 1.0)) / np.pi


def mean_angle_change(directions: list[np.ndarray] | np.ndarray, pairs: np.ndarray) -> np.ndarray:
    """MAAC: per-pair mean absolute frame-to-frame change of the included angles (HA2G eq. 10).

    ``MAAC_p = sum_s sum_t |theta_{p,s,t+1} - theta_{p,s,t}| / (sum_s (T_s - 1))`` over clips ``s``.
    Compute it on *training* data and pass it to :func:`angle_change_curve`. Pairs that never
    move get a MAAC of round-off size; :func:`drop_rigid_pairs` leaves them out of the curve.

    Parameters
    ----------
    directions : (T, V, 3) array or list of such (clips or takes)
        Direction vectors (palm normals already appended if ``pairs`` use them).
    pairs : (P, 2) int

    Returns
    -------
    (P,) float64, units of pi radians per frame.

    Examples
    --------
    >>> angle = np.array([0.0, 0.5, 0.5, 1.5]) * np.pi / 4  # (T,) radians of the second vector
    >>> directions = np.zeros((4, 2, 3))
    >>> directions[:, 0] = [1, 0, 0]
    >>> directions[:, 1, 0], directions[:, 1, 1] = np.cos(angle), np.sin(angle)
    >>> mean_angle_change(directions, np.array([[0, 1]])).round(6)  # (0.5 + 0 + 1) / 4 / 3 in units of pi
    array([0.125])
    """
    items = directions if isinstance(directions, (list, tuple)) else [directions]
    total, count = None, 0
    for d in items:
        th = included_angles(d, pairs)
        s = np.abs(np.diff(th, axis=0)).sum(axis=0)
        total = s if total is None else total + s
        count += th.shape[0] - 1
    if total is None or count == 0:
        raise ValueError("directions must hold at least one clip with 2 or more frames")
    return total / count


RIGID_RTOL = 1e-5
"""Relative MAAC below which an angle pair counts as rigid (:func:`drop_rigid_pairs`)."""


def drop_rigid_pairs(
    pairs: np.ndarray, change_angle: np.ndarray, *, rtol: float = RIGID_RTOL
) -> tuple[np.ndarray, np.ndarray]:
    """Keep the angle pairs that move: ``MAAC_p > rtol * max_q MAAC_q``.

    HA2G divides every pair's angle change by its MAAC (:func:`angle_change_curve`). A pair
    whose two vectors are rigidly linked (on BEAT's skeleton: nose->eye vs eye->ear, both
    sides) has a MAAC of pure round-off (1e-16 on float64 takes, 9e-10 on the float32 training
    windows), and dividing by it turns round-off, or any jitter of a generated head, into
    normalised changes of order 1 to 1e7 that create or remove motion beats. Such pairs carry
    no motion beat and are left out of the mean.

    The threshold is relative, so it does not depend on the angle unit or the frame rate:
    ``rtol = 1e-5`` is about 100 float32 epsilons (1.19e-7), below which a pair's typical change
    cannot be told from rounding of float32-stored directions. On ``data_samples/`` the rigid
    pairs sit at 1e-7 of the largest MAAC and the slowest real pair (left finger bases) at
    9e-4 of it, two orders of magnitude on either side. HA2G's own TED Expressive statistics
    (smallest / largest MAAC = 0.02) lose no pair, so its legacy protocol is unchanged.

    Parameters
    ----------
    pairs : (P, 2) int
        Angle pairs.
    change_angle : (P,) float >= 0
        MAAC per pair (:func:`mean_angle_change` on training data).
    rtol : float >= 0
        Relative threshold; 0 keeps every pair with a positive MAAC.

    Returns
    -------
    pairs : (P', 2) int64
        The moving pairs, in their order.
    change_angle : (P',) float64
        Their MAAC.

    Examples
    --------
    >>> p, ca = drop_rigid_pairs(np.array([[0, 1], [1, 2]]), np.array([0.01, 3e-18]))
    >>> p.tolist(), ca.tolist()
    ([[0, 1]], [0.01])
    """
    pr = np.asarray(pairs, dtype=np.int64)
    ca = as_array(change_angle, "change_angle", ndim=1)
    if pr.ndim != 2 or pr.shape[1] != 2:
        raise ValueError(f"pairs must be (P, 2) indices, got shape {pr.shape}")
    if ca.shape[0] != pr.shape[0]:
        raise ValueError(f"change_angle must have one entry per pair ({pr.shape[0]}), got shape {ca.shape}")
    if not np.all(np.isfinite(ca)) or np.any(ca < 0):
        raise ValueError("change_angle must be finite and >= 0 for every pair")
    if float(rtol) < 0:
        raise ValueError(f"rtol must be >= 0, got {rtol}")
    keep = ca > float(rtol) * (ca.max() if ca.size else 0.0)
    if not keep.any():
        raise ValueError(
            "change_angle has no moving pair (was it computed from motion in which no pair ever moves?)"
        )
    return pr[keep], ca[keep]


def angle_change_curve(
    directions: np.ndarray, pairs: np.ndarray, change_angle: np.ndarray, *, rigid_rtol: float = RIGID_RTOL
) -> np.ndarray:
    """HA2G's normalised angle change rate per frame.

    ``c_t = (1/P') sum_p |theta_{t,p} - theta_{t-1,p}| / MAAC_p`` for t >= 1, ``c_0 = 0``, over
    the P' pairs that move (:func:`drop_rigid_pairs`; HA2G averages all P, which is the same
    whenever no pair is rigid, as with HA2G's own statistics).

    Parameters
    ----------
    directions : (T, V, 3) float
    pairs : (P, 2) int
    change_angle : (P,) float >= 0
        MAAC per pair (:func:`mean_angle_change` on training data).
    rigid_rtol : float
        ``rtol`` of :func:`drop_rigid_pairs`.

    Returns
    -------
    (T,) float64, dimensionless (1 = a typical frame).

    Examples
    --------
    >>> angle = np.array([0.0, 0.5, 0.5, 1.5]) * np.pi / 4
    >>> directions = np.zeros((4, 2, 3))
    >>> directions[:, 0] = [1, 0, 0]
    >>> directions[:, 1, 0], directions[:, 1, 1] = np.cos(angle), np.sin(angle)
    >>> angle_change_curve(directions, np.array([[0, 1]]), np.array([0.125])).round(6)  # change / MAAC
    array([0., 1., 0., 2.])
    """
    pr, ca = drop_rigid_pairs(pairs, change_angle, rtol=rigid_rtol)
    th = included_angles(directions, pr)
    c = (np.abs(np.diff(th, axis=0)) / ca).mean(axis=1)
    return np.concatenate([[0.0], c])


def angle_change_beats(curve: np.ndarray, fps: float, *, threshold: float = 0.03) -> np.ndarray:
    """HA2G motion beats: strict local minima of the angle change rate with a clear drop.

    Frame ``t`` in ``[2, T-2]`` is a beat when ``c_t < c_{t-1}``, ``c_t < c_{t+1}`` and
    ``max(c_{t-1} - c_t, c_{t+1} - c_t) >= threshold`` (HA2G: t in [2, 32] for 34 frames).

    Parameters
    ----------
    curve : (T,) float
        :func:`angle_change_curve`.
    fps : float
    threshold : float
        Minimum drop (0.03 in HA2G).

    Returns
    -------
    (K,) float64 beat times in seconds, ``t / fps``.

    Examples
    --------
    >>> curve = np.array([0.0, 1.0, 1.0, 0.2, 1.0, 1.0, 0.99, 1.0, 1.0])
    >>> angle_change_beats(curve, fps=15)  # frame 3 (a clear drop); frame 6 drops by only 0.01
    array([0.2])
    """
    c = np.asarray(curve, dtype=np.float64)
    if c.ndim != 1:
        raise ValueError(f"curve must be 1-D, got shape {c.shape}")
    t = np.arange(2, c.shape[0] - 1)
    if t.size == 0:
        return np.zeros(0, dtype=np.float64)
    prev, cur, nxt = c[t - 1], c[t], c[t + 1]
    ok = (cur < prev) & (cur < nxt) & ((prev - cur >= threshold) | (nxt - cur >= threshold))
    return t[ok] / positive(fps, "fps")


# ----------------------------------------------------------------------------- score
def nearest_distance(query: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Distance from each query time to the nearest reference time (``np.searchsorted``).

    Parameters
    ----------
    query : (Q,) float, seconds
    reference : (R,) float, seconds, R >= 1 (sorted internally)

    Returns
    -------
    (Q,) float64 seconds; ``inf`` everywhere when ``reference`` is empty.

    Examples
    --------
    >>> nearest_distance(np.array([0.1, 0.9, 2.0]), np.array([1.0, 0.0])).round(6)
    array([0.1, 0.1, 1. ])
    """
    q = np.asarray(query, dtype=np.float64).ravel()
    r = np.sort(np.asarray(reference, dtype=np.float64).ravel())
    if r.size == 0:
        return np.full(q.shape, np.inf)
    i = np.searchsorted(r, q)
    left = r[np.clip(i - 1, 0, r.size - 1)]
    right = r[np.clip(i, 0, r.size - 1)]
    return np.minimum(np.abs(q - left), np.abs(q - right))


def gaussian_alignment(query: np.ndarray, reference: np.ndarray, sigma: float) -> float:
    """``(1/|Q|) sum_q exp(-min_r (q - r)^2 / (2 sigma^2))``; NaN when ``query`` is empty.

    Parameters
    ----------
    query, reference : (Q,), (R,) float seconds
    sigma : float, seconds

    Returns
    -------
    float in [0, 1] (0 when ``reference`` is empty), NaN for an empty ``query``.

    Examples
    --------
    >>> round(gaussian_alignment(np.array([1.0, 2.0]), np.array([1.0, 2.3]), sigma=0.3), 4)  # (1 + exp(-0.5)) / 2
    0.8033
    >>> gaussian_alignment(np.array([1.0]), np.array([]), sigma=0.3)
    0.0
    """
    s = positive(sigma, "sigma")
    q = np.asarray(query, dtype=np.float64).ravel()
    if q.size == 0:
        return float("nan")
    d = nearest_distance(q, reference)
    return float(np.mean(np.exp(-(d**2) / (2 * s * s))))


def alignment_score(
    audio_times: np.ndarray, motion_times: np.ndarray, sigma: float, direction: str = "audio_to_motion"
) -> float:
    """Gaussian beat alignment in the chosen direction.

    ``"audio_to_motion"`` (both references): average over audio beats of the Gaussian of the
    distance to the nearest motion beat — it rewards motion beats near every audio beat and
    ignores extra motion beats. ``"motion_to_audio"`` swaps the roles; ``"symmetric"`` is the
    mean of both.

    Returns
    -------
    float in [0, 1]; NaN when the query set is empty.

    Examples
    --------
    >>> audio, motion = np.array([1.0, 2.0]), np.array([1.0, 2.3, 5.0])
    >>> round(alignment_score(audio, motion, 0.3), 4)  # the extra motion beat at 5 s is ignored
    0.8033
    >>> round(alignment_score(audio, motion, 0.3, "motion_to_audio"), 4)  # (1 + exp(-0.5) + ~0) / 3
    0.5355
    """
    if direction == "audio_to_motion":
        return gaussian_alignment(audio_times, motion_times, sigma)
    if direction == "motion_to_audio":
        return gaussian_alignment(motion_times, audio_times, sigma)
    if direction == "symmetric":
        a = gaussian_alignment(audio_times, motion_times, sigma)
        b = gaussian_alignment(motion_times, audio_times, sigma)
        return float(np.nanmean([a, b])) if np.isfinite([a, b]).any() else float("nan")
    raise ValueError(f"direction must be one of {DIRECTIONS}, got {direction!r}")
