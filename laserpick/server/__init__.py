"""The laserpick server: the operator-session web API and its journal."""
