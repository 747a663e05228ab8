import os
import sys

import pytest
import torch

TOOL_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, TOOL_DIR)
torch.set_num_threads(1)


@pytest.fixture
def tool_dir():
    return TOOL_DIR
