"""Pictures, videos and reports of every wing's results. No wing imports this package."""
