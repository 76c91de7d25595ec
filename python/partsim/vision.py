"""partsim.vision: the perception benchmark of the SAPIEN paper (movable-part detection and
motion-attribute estimation).

COCO masks and run-length encoding (encode_mask, decode_rle, rle_area, rle_bbox, rle_iou,
compress_rle_counts, decompress_rle_counts) and the evaluators: evaluate_detection (AP at mask
IoU 0.5 per part category and the mAP, COCO's protocol) and evaluate_motion (the columns of the
paper's Table 2). They are the C++ vision layer's, bound in the extension; files and formats are
described in docs/vision.md. Example::

    import partsim.vision as vision
    e = vision.evaluate_detection("instances_test.json", "results.json")
    print(e.to_markdown(), e.map)
"""

from ._partsim import _vision as _ext

# the C++ layer's names (their __module__ says partsim.vision)
CategoryAp = _ext.CategoryAp
DetectionEvaluation = _ext.DetectionEvaluation
MotionEvaluation = _ext.MotionEvaluation
compress_rle_counts = _ext.compress_rle_counts
decode_rle = _ext.decode_rle
decompress_rle_counts = _ext.decompress_rle_counts
encode_mask = _ext.encode_mask
evaluate_detection = _ext.evaluate_detection
evaluate_motion = _ext.evaluate_motion
rle_area = _ext.rle_area
rle_bbox = _ext.rle_bbox
rle_iou = _ext.rle_iou

__all__ = [
    "CategoryAp", "DetectionEvaluation", "MotionEvaluation", "compress_rle_counts", "decode_rle",
    "decompress_rle_counts", "encode_mask", "evaluate_detection", "evaluate_motion", "rle_area",
    "rle_bbox", "rle_iou",
]
