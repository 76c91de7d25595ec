"""Where PyTorch work runs: the one rule of partsim's learners and perception baselines."""


def resolve_device(device: str) -> str:
    """"auto": "cuda" when PyTorch sees a GPU, else "cpu"; "cpu" and "cuda" as they are (a
    ValueError for "cuda" without one, or anything else)."""
    import torch

    if device == "auto":
        return "cuda" if torch.cuda.is_available() else "cpu"
    if device == "cuda" and not torch.cuda.is_available():
        raise ValueError("--device cuda: PyTorch sees no GPU (this torch is "
                         f"{torch.__version__}; Debian's is built for the CPU only)")
    if device not in ("cpu", "cuda"):
        raise ValueError(f"--device wants auto, cpu or cuda, got {device!r}")
    return device
