# Install rules and package files; filled in by the issue-7 work.
