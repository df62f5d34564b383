"""The end-to-end runners on top: plan, mandrel builds, batch, reports and exports."""
