#!/usr/bin/env python3
"""Writes the tiny ONNX models checked into tests/data/models/ (each well under 10 KB).

Their outputs are exact functions of the input, so the depth spec and detector decoder tests can
compare against hand-computed values:
  depth_metric.onnx     1x3x48x64 -> 1x1x48x64  y = mean over channels of the network input
  depth_inverse.onnx    1x3x48x64 -> 1x48x64    same, rank-3 output
  depth_disparity.onnx  1x3x48x64 -> 1x1x24x32  same, 2x2 average pooled (half-resolution output)
  depth_dynamic.onnx    1x3xHxW   -> 1x1xHxW    same, dynamic height and width
  depth_bad_output.onnx 1x3x48x64 -> 1x2x48x64  two channels: must be rejected at load
  det_yolov5.onnx       1x3x64x64 -> 1x4x13     constant YOLOv5 rows (8 classes)
  det_yolov8.onnx       1x3x64x64 -> 1x12x4     constant YOLOv8 columns (8 classes)
  det_yolov8_probe.onnx 1x3x64x64 -> 1x5x1      one YOLOv8 box whose class-0 score is the mean of
                                                input channel 0: checks colour order, /255 and
                                                the letterbox padding value
Models that must be rejected at load with one line naming the file (bad-input tests):
  depth_uint8_input.onnx    uint8 1x3x48x64 -> float 1x1x48x64   input of the wrong type
  depth_double_output.onnx  1x3x48x64 -> double 1x1x48x64        output of the wrong type
  depth_opset99.onnx        depth_metric declaring ai.onnx opset 99 (no runtime has it)
  det_double_output.onnx    det_yolov8 with a double output
The detector heads ignore the image (0 * mean(input) is added so the input stays in the graph).

Run with the system Python (python3-onnx): /usr/bin/python3 tools/make_test_models.py
"""
import os

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OUT_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data", "models")
OPSET = 13


def save(graph, name, opset=OPSET):
    model = helper.make_model(graph, opset_imports=[helper.make_opsetid("", opset)],
                              producer_name="ademono make_test_models.py")
    model.ir_version = 7
    if opset == OPSET:  # the checker itself rejects an unknown opset
        onnx.checker.check_model(model)
    path = os.path.join(OUT_DIR, name)
    onnx.save(model, path)
    print(f"{path}: {os.path.getsize(path)} bytes")


def image_input(height, width, element_type=TensorProto.FLOAT):
    return helper.make_tensor_value_info("image", element_type, [1, 3, height, width])


def channel_mean_model(name, out_shape, height=48, width=64, squeeze=False, pool=False,
                       channels=1, input_type=TensorProto.FLOAT, output_type=TensorProto.FLOAT,
                       opset=OPSET):
    nodes = []
    source = "image"
    if input_type != TensorProto.FLOAT:
        nodes.append(helper.make_node("Cast", ["image"], ["image_float"], to=TensorProto.FLOAT))
        source = "image_float"
    nodes.append(helper.make_node("ReduceMean", [source], ["mean"], axes=[1], keepdims=1))
    last = "mean"
    if pool:
        nodes.append(helper.make_node("AveragePool", [last], ["pooled"], kernel_shape=[2, 2],
                                      strides=[2, 2]))
        last = "pooled"
    if channels > 1:
        nodes.append(helper.make_node("Concat", [last] * channels, ["stacked"], axis=1))
        last = "stacked"
    if squeeze:
        axes = numpy_helper.from_array(np.array([1], dtype=np.int64), "squeeze_axes")
        nodes.append(helper.make_node("Constant", [], ["axes"], value=axes))
        nodes.append(helper.make_node("Squeeze", [last, "axes"], ["squeezed"]))
        last = "squeezed"
    if output_type != TensorProto.FLOAT:
        nodes.append(helper.make_node("Cast", [last], ["depth"], to=output_type))
    else:
        nodes.append(helper.make_node("Identity", [last], ["depth"]))
    graph = helper.make_graph(nodes, name, [image_input(height, width, input_type)],
                              [helper.make_tensor_value_info("depth", output_type, out_shape)])
    save(graph, name + ".onnx", opset)


def constant_head(name, values, out_name="output", output_type=TensorProto.FLOAT):
    values = np.asarray(values, dtype=np.float32)
    nodes = [
        helper.make_node("Constant", [], ["head"], value=numpy_helper.from_array(values, "head")),
        helper.make_node("ReduceMean", ["image"], ["image_mean"], keepdims=0),
        helper.make_node("Constant", [], ["zero"],
                         value=numpy_helper.from_array(np.array(0, dtype=np.float32), "zero")),
        helper.make_node("Mul", ["image_mean", "zero"], ["nothing"]),
    ]
    if output_type != TensorProto.FLOAT:
        nodes.append(helper.make_node("Add", ["head", "nothing"], ["sum"]))
        nodes.append(helper.make_node("Cast", ["sum"], [out_name], to=output_type))
    else:
        nodes.append(helper.make_node("Add", ["head", "nothing"], [out_name]))
    graph = helper.make_graph(nodes, name, [image_input(64, 64)],
                              [helper.make_tensor_value_info(out_name, output_type,
                                                             list(values.shape))])
    save(graph, name + ".onnx")


def input_probe_head(name):
    """YOLOv8 layout, one anchor: box (32, 32, 10, 10), class-0 score = mean of channel 0."""
    box = numpy_helper.from_array(np.array([32, 32, 10, 10], dtype=np.float32).reshape(1, 4, 1),
                                  "box")
    shape = numpy_helper.from_array(np.array([1, 1, 1], dtype=np.int64), "score_shape")
    starts = numpy_helper.from_array(np.array([0], dtype=np.int64), "starts")
    ends = numpy_helper.from_array(np.array([1], dtype=np.int64), "ends")
    axes = numpy_helper.from_array(np.array([1], dtype=np.int64), "axes")
    nodes = [
        helper.make_node("Constant", [], ["box"], value=box),
        helper.make_node("Constant", [], ["score_shape"], value=shape),
        helper.make_node("Constant", [], ["starts"], value=starts),
        helper.make_node("Constant", [], ["ends"], value=ends),
        helper.make_node("Constant", [], ["axes"], value=axes),
        helper.make_node("Slice", ["image", "starts", "ends", "axes"], ["channel0"]),
        helper.make_node("ReduceMean", ["channel0"], ["mean0"], keepdims=0),
        helper.make_node("Reshape", ["mean0", "score_shape"], ["score"]),
        helper.make_node("Concat", ["box", "score"], ["output0"], axis=1),
    ]
    graph = helper.make_graph(nodes, name, [image_input(64, 64)],
                              [helper.make_tensor_value_info("output0", TensorProto.FLOAT,
                                                             [1, 5, 1])])
    save(graph, name + ".onnx")


def one_hot(class_id, prob, num_classes=8, rest=0.05):
    probs = [rest] * num_classes
    probs[class_id] = prob
    return probs


# Detector rows (cx, cy, w, h in network-input pixels). The tests expect, at score 0.3, NMS 0.45:
#   row 0 kept (class 1, 0.9 * 0.8 = 0.72); row 1 suppressed by row 0 (same class, IoU 0.90);
#   row 2 kept (class 2, 0.6 * 0.9 = 0.54, overlaps row 0 but another class); row 3 below the
#   score threshold (0.5 * 0.5 = 0.25).
DET_BOXES = [
    ([32, 32, 20, 10], 0.9, one_hot(1, 0.8)),
    ([33, 32, 20, 10], 0.8, one_hot(1, 0.7)),
    ([34, 33, 18, 12], 0.6, one_hot(2, 0.9)),
    ([10, 50, 8, 8], 0.5, one_hot(0, 0.5)),
]


def main():
    os.makedirs(OUT_DIR, exist_ok=True)
    channel_mean_model("depth_metric", [1, 1, 48, 64])
    channel_mean_model("depth_inverse", [1, 48, 64], squeeze=True)
    channel_mean_model("depth_disparity", [1, 1, 24, 32], pool=True)
    channel_mean_model("depth_dynamic", [1, 1, "height", "width"], height="height", width="width")
    channel_mean_model("depth_bad_output", [1, 2, 48, 64], channels=2)

    v5 = [box + [obj] + probs for box, obj, probs in DET_BOXES]
    constant_head("det_yolov5", [v5])
    # YOLOv8 has no objectness: class scores are obj * cls of the same rows, transposed.
    v8 = [box + [obj * p for p in probs] for box, obj, probs in DET_BOXES]
    constant_head("det_yolov8", [np.asarray(v8).T.tolist()], out_name="output0")
    input_probe_head("det_yolov8_probe")

    channel_mean_model("depth_uint8_input", [1, 1, 48, 64], input_type=TensorProto.UINT8)
    channel_mean_model("depth_double_output", [1, 1, 48, 64], output_type=TensorProto.DOUBLE)
    channel_mean_model("depth_opset99", [1, 1, 48, 64], opset=99)
    constant_head("det_double_output", [np.asarray(v8).T.tolist()], out_name="output0",
                  output_type=TensorProto.DOUBLE)


if __name__ == "__main__":
    main()
