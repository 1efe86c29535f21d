"""Retrieval stage: instruction parsing, cosine ranking (eq. 16), MMR, spatial predicates
(eq. 17), verification (AGENT) and explanations (paper 3.4)."""

from capnav.retrieval.config import RetrievalConfig
from capnav.retrieval.query import ParsedQuery, parse_instruction, validate_instruction
from capnav.retrieval.result import QueryResult
from capnav.retrieval.retriever import Retriever, check_map_embeddings
from capnav.retrieval.verifier import VERIFIERS, Candidate, OfflineVerifier, Verifier, create_verifier

__all__ = ["VERIFIERS", "Candidate", "OfflineVerifier", "ParsedQuery", "QueryResult", "RetrievalConfig", "Retriever",
           "Verifier", "check_map_embeddings", "create_verifier", "parse_instruction", "validate_instruction"]
