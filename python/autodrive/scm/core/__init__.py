"""The SCM's configuration (config), database engine and migrations (db) and passwords and
session secrets (security)."""
