"""Metrics, baselines and the evaluation harness."""

from gnngarment.evaluation.evaluate import (
    METRICS,
    EvaluationReport,
    evaluate,
    predict,
    write_report,
)

__all__ = ["METRICS", "EvaluationReport", "evaluate", "predict", "write_report"]
