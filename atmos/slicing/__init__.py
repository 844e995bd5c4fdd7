"""Work split over frames: three texture sets (A, B shown interpolated; C written a few slices per frame).

``TripleSet`` holds the three sets, ``SlicedJob`` runs a chain of ``SliceTask`` slices into C and
rotates when C is complete, ``FrameScheduler`` hands out each frame's slices (sliced or naive mode).
"""
from atmos.slicing.job import JobStats, Measure, SliceContext, SlicedJob, SliceTask, perf_measure, synced_measure, timer_query_measure, gpu_measure
from atmos.slicing.scheduler import MODES, FrameScheduler, FrameStats
from atmos.slicing.texture_sets import TextureSet, TripleSet, make_texture

__all__ = ["TextureSet", "TripleSet", "make_texture", "SliceTask", "SliceContext", "SlicedJob", "JobStats",
           "Measure", "perf_measure", "synced_measure", "timer_query_measure", "gpu_measure", "FrameScheduler", "FrameStats", "MODES"]
