"""Fixtures for the language tests: tiny randomly initialised models built and saved here."""

from __future__ import annotations

from pathlib import Path

import pytest

WORDS = ("a white grey red blue green black brown sofa couch chair table bed lamp plant wooden "
         "fabric leather metal large small round curved the with and of is next to kitchen").split()


def write_vocab(folder: Path) -> Path:
    letters = [chr(c) for c in range(97, 123) if chr(c) not in WORDS]
    vocab = ["[PAD]", "[UNK]", "[CLS]", "[SEP]", "[MASK]", ",", ".", *WORDS, *letters]
    path = folder / "vocab.txt"
    path.write_text("\n".join(vocab) + "\n")
    return path


@pytest.fixture(scope="session")
def tiny_st_model(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A 1-layer, 32-d BERT with mean pooling saved as a sentence-transformers folder."""
    torch = pytest.importorskip("torch")
    pytest.importorskip("sentence_transformers")
    from sentence_transformers import SentenceTransformer, models
    from transformers import BertConfig, BertModel, BertTokenizer

    torch.manual_seed(0)
    base = tmp_path_factory.mktemp("tiny_bert")
    vocab = write_vocab(base)
    words = vocab.read_text().split()
    cfg = BertConfig(vocab_size=len(words), hidden_size=32, num_hidden_layers=1,
                     num_attention_heads=2, intermediate_size=64, max_position_embeddings=64)
    BertModel(cfg).save_pretrained(base)
    BertTokenizer(vocab={w: i for i, w in enumerate(words)}, do_lower_case=True).save_pretrained(base)
    out = tmp_path_factory.mktemp("tiny_st")
    word = models.Transformer(str(base), max_seq_length=48)
    pool = models.Pooling(word.get_embedding_dimension(), pooling_mode="mean")
    SentenceTransformer(modules=[word, pool], device="cpu").save(str(out))
    return out
