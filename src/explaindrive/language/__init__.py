"""The language layer: speech, command interpretation (LLM-1), explanation trigger
(LLM-2) and explanation generator (LLM-3), with an offline and an OpenAI backend."""
